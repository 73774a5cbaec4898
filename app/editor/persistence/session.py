"""Session files (``.rwsession``): a modelling session to come back to.

A session holds the structure as read (embedded: it opens when the original file has
moved), the whole undo history at its position, the level, segment and ribbon kind
(:func:`~app.editor.persistence.recording.recording`), and a ``view`` record: the display
layers and colouring, the camera, the labels and measurements, the selection and the compared
structures (embedded too). It is the
record format of journals (:mod:`app.editor.persistence.records`), written atomically.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from app.editor.persistence import records
from app.editor.persistence.schema import SELECTION
from core.protein.writing import atomic_write

SUFFIX = ".rwsession"


class SessionError(ValueError):
    """A session file that cannot be opened; the message names the file and says why."""


@dataclass(frozen=True)
class ComparedFile:
    """A compared structure of a session: its file name and bytes, chain and visibility."""

    path: Path
    source: bytes
    chain: str
    visible: bool


@dataclass(frozen=True)
class View:
    """What a session shows besides the document."""

    layers: list[str]
    colouring: str
    fat_helices: bool
    camera: list[list[float]]
    compared: list[ComparedFile]
    helix_cylinders: bool = False
    measurements: list[dict] = field(default_factory=list)
    """Each label and measurement: its atoms (coordinate rows) and whether it labels a residue."""
    slab: list[float] | None = None
    """The clipping slab (Å in front of and behind the centre), or None."""
    selection: tuple[np.ndarray, np.ndarray] = (np.empty(0, np.int64), np.empty(0, np.int64))
    """The selected residues (residue-table rows) and groups (coordinate rows)."""

    def record(self) -> records.Record:
        """The ``view`` record of this view."""
        fields = {"layers": self.layers, "colouring": self.colouring, "fat_helices": self.fat_helices,
                  "helix_cylinders": self.helix_cylinders, "measurements": self.measurements, "slab": self.slab,
                  "camera": self.camera,
                  "compared": [{"path": str(c.path), "chain": c.chain, "visible": c.visible} for c in self.compared]}
        arrays = {f"compared_{k}": np.frombuffer(c.source, dtype=np.uint8) for k, c in enumerate(self.compared)}
        arrays |= {name: np.asarray(rows, dtype=np.int64) for name, rows in zip(SELECTION, self.selection, strict=True)}
        return records.Record("view", fields, arrays)

    @classmethod
    def of(cls, record: records.Record) -> View:
        """The view of a ``view`` record."""
        fields = record.fields
        compared = [ComparedFile(Path(c["path"]), record.arrays[f"compared_{k}"].tobytes(), c["chain"], c["visible"])
                    for k, c in enumerate(fields["compared"])]
        selection = tuple(record.arrays.get(name, np.empty(0, np.int64)) for name in SELECTION)
        return cls(fields["layers"], fields["colouring"], fields["fat_helices"], fields["camera"], compared,
                   fields.get("helix_cylinders", False), fields.get("measurements", []),
                   _slab(fields.get("slab")), selection)  # (these four are newer than the format)


def _slab(value: object) -> list[float] | None:
    """A session's slab, two positive distances (Å), or None (also for anything else)."""
    if isinstance(value, list) and len(value) == 2 and all(isinstance(v, (int, float)) and 0 < v < 1e4 for v in value):
        return [float(v) for v in value]
    return None


def write(path: Path, recording: list[records.Record], view: View) -> None:
    """Write a session atomically (a temporary file beside ``path``, then a rename)."""
    atomic_write(Path(path), records.MAGIC + b"".join(records.encode(r) for r in [*recording, view.record()]))


@dataclass(frozen=True)
class Contents:
    """What a session file holds, as far as it is valid (:func:`read`)."""

    recording: list[records.Record]
    """The document's recording (:func:`~app.editor.persistence.recording.replay`)."""
    view: View | None
    """What the window showed; None if its record was damaged or missing."""
    left_out: list[str]
    """What was passed over, for people (damaged bytes, records that break their rules)."""


def read(path: Path) -> Contents:
    """The session at ``path`` as far as it is valid (raises SessionError for a file that is not
    a session, of a newer format, or whose structure cannot be read)."""
    path = Path(path)
    try:
        reading = records.read(path)
    except OSError as error:
        raise SessionError(f"{path}: cannot read ({error.strerror})") from None
    except records.RecordError as error:
        raise SessionError(f"{path}: {error}") from None
    if not reading.records:
        raise SessionError(f"{path}: the session file is damaged (cut off inside its structure)")
    views = [r for r in reading.records if r.kind == "view"]
    left_out = list(reading.skipped)
    if reading.cut_off:
        left_out.append("the file is cut off: what followed is lost")
    if not views:
        left_out.append("no view record: the window's view stays as it is")
    return Contents([r for r in reading.records if r.kind != "view"], View.of(views[-1]) if views else None, left_out)
