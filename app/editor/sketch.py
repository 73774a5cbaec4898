"""The molecule sketched while the editor loads: its Cα (and nucleic acids' P) trace read with gemmi and
drawn with Qt's painter where the 3D view will be, seen from the view's first direction, on its
background, in the ribbon's colours. No numpy and no VTK: ``ribbonwave FILE`` shows it a few
tens of milliseconds after its window, and the 3D view takes its place once loaded."""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from PySide6.QtCore import QLineF, Qt
from PySide6.QtGui import QColor, QLinearGradient, QPainter, QPaintEvent, QPen
from PySide6.QtWidgets import QSizePolicy, QWidget

from app.editor.scene.looks import BACKGROUND, FIT_CLOSER, NUCLEIC_BACKBONE, RGB, SS_COLOURS, VIEW_ANGLE
from core.geometry.principal import Vector, principal_directions
from core.protein.input_files import looks_like_mmcif, read_bytes, text_of

if TYPE_CHECKING:
    import gemmi

HALF_WIDTHS = {"H": 1.0, "E": 1.0, "C": 0.35, "N": 0.9}
"""Å: about the half-width the ribbon shows of a helix, a strand and a loop, and the nucleic
acids' backbone tube ('N')."""
RIBBON_REACH = 1.4
"""Å: how far the ribbon reaches beyond the trace (the view's fit takes in the ribbon)."""
FOG = 0.45
"""How much of the background the farthest part of the trace takes on (depth cueing)."""
DEPTH_BANDS = 64
"""The trace's steps are drawn in this many bands of depth, each band's of one kind at once with
one pen (a capsid's hundred thousand steps in a fraction of a second)."""
LARGEST_SKETCHED = 4 * 2**20
"""Bytes, as stored: a larger file is not sketched (read twice, its 3D view would come seconds later)."""
LONGEST_STEP = {"protein": 4.2, "nucleic": 9.0}
"""Å: the longest step between the Cα (as the structure's segments: ``MAX_CA_STEP``) or the P
(as the nucleic acids' tube: ``GAP``) of consecutive residues drawn; a longer one is a gap."""
COLOURS = {**SS_COLOURS, "N": NUCLEIC_BACKBONE}
"""The colour of each kind of step, as the 3D view's."""


@dataclass(frozen=True)
class Run:
    """Connected residues of a polymer: their Cα (of a nucleic acid, P) positions and their kinds:
    secondary structure ('H', 'E', 'C'), or 'N' for nucleotides."""

    positions: tuple[Vector, ...]
    kinds: str


@dataclass(frozen=True)
class Trace:
    """The runs of a structure's polymers, and the points the 3D view first looks at (as the
    scene: the Cα, or all atoms of a structure without protein)."""

    runs: tuple[Run, ...]
    looked_at: tuple[Vector, ...]

    @functools.cached_property
    def directions(self) -> tuple[Vector, Vector]:
        """The view's first direction (from the structure towards the camera) and up: the
        directions of least and middle extent of :attr:`looked_at`."""
        n = len(self.looked_at)
        centre = [sum(p[k] for p in self.looked_at) / n for k in range(3)]
        scatter = [[sum((p[i] - centre[i]) * (p[j] - centre[j]) for p in self.looked_at) for j in range(3)]
                   for i in range(3)]
        towards, up, _ = principal_directions(scatter)
        return towards, up

    @functools.cached_property
    def bounds(self) -> tuple[Vector, Vector]:
        """The lowest and highest coordinates of the runs, widened by the ribbon's reach."""
        points = [p for run in self.runs for p in run.positions]
        low = tuple(min(p[k] for p in points) - RIBBON_REACH for k in range(3))
        high = tuple(max(p[k] for p in points) + RIBBON_REACH for k in range(3))
        return low, high  # type: ignore[return-value]

    def camera(self, aspect: float) -> Camera:
        """The 3D view's first camera on the structure in a view ``aspect`` (width / height) wide."""
        return Camera.fitting(*self.directions, *self.bounds, aspect)


def read_trace(path: Path, model: int = 1) -> Trace | None:
    """The trace of model ``model`` (from 1) of the structure file ``path``; None where it has no
    polymer of two connected residues, is larger than :data:`LARGEST_SKETCHED` or cannot be read
    (reading it in full says why)."""
    from core.protein.parsing import parse  # (here: the window's frame is painted before gemmi loads)

    try:
        if path.stat().st_size > LARGEST_SKETCHED:
            return None
        text = text_of(path, read_bytes(path))[0]
        st = parse(text, "mmcif" if looks_like_mmcif(text) else "pdb", path)
        if not 1 <= model <= len(st):
            return None
        chosen = st[model - 1]
        runs = _runs(chosen, _secondary_structure(st, chosen))
        looked_at = [p for run in runs if run.kinds[0] != "N" for p in run.positions]
        if runs and not looked_at:
            looked_at = [(atom.pos.x, atom.pos.y, atom.pos.z) for chain in chosen for residue in chain for atom in residue]
    except Exception:  # noqa: BLE001 (anything the full read reports, with its reason)
        return None
    return Trace(runs, tuple(looked_at)) if runs else None


def _secondary_structure(st: gemmi.Structure, model: gemmi.Model) -> dict[tuple[str, int, str], str]:
    """'H' or 'E' by (chain, number, insertion code) of the residues in the file's helices and strands."""
    ranges = [(helix.start, helix.end, "H") for helix in st.helices]
    ranges += [(strand.start, strand.end, "E") for sheet in st.sheets for strand in sheet.strands]
    kinds = {}
    for start, end, kind in ranges:
        chain = model.find_chain(start.chain_name)
        inside = False
        for residue in chain or ():
            inside = inside or residue.seqid == start.res_id.seqid
            if inside:
                kinds[(chain.name, residue.seqid.num, residue.seqid.icode)] = kind
                if residue.seqid == end.res_id.seqid:
                    break
    return kinds


def _runs(model: gemmi.Model, kinds: dict[tuple[str, int, str], str]) -> tuple[Run, ...]:
    """The model's polymers, cut at their gaps."""
    runs = []
    for chain in model:
        polymer = chain.get_polymer()
        nucleic = polymer.check_polymer_type().name in ("Dna", "Rna", "DnaRnaHybrid")
        positions: list[Vector] = []
        letters: list[str] = []
        for residue in polymer:
            atom = (residue.find_atom("P", "*") or residue.find_atom("C4'", "*")) if nucleic else residue.find_atom("CA", "*")
            if atom is None:
                continue
            position = (atom.pos.x, atom.pos.y, atom.pos.z)
            if positions and math.dist(positions[-1], position) > LONGEST_STEP["nucleic" if nucleic else "protein"]:
                runs.append(Run(tuple(positions), "".join(letters)))
                positions, letters = [], []
            positions.append(position)
            letters.append("N" if nucleic else kinds.get((chain.name, residue.seqid.num, residue.seqid.icode), "C"))
        runs.append(Run(tuple(positions), "".join(letters)))
    return tuple(run for run in runs if len(run.positions) > 1)


@dataclass(frozen=True)
class Camera:
    """The 3D view's first camera in direction (as :meth:`app.editor.scene.scene.Scene.reset_camera`
    turns it: along the Cα's direction of least extent), fitted to the trace as VTK fits a scene, a
    little closer. (The view's fit takes in its control points too, which at a coarse level reach
    beyond the molecule: the view then starts farther away.)"""

    focal: Vector
    right: Vector
    up: Vector
    towards: Vector
    """From the focal point to the camera."""
    distance: float

    @classmethod
    def fitting(cls, towards: Vector, up: Vector, low: Vector, high: Vector, aspect: float) -> Camera:
        """Looking along ``-towards`` with ``up`` up, fitting the box from ``low`` to ``high`` in
        a view ``aspect`` (width / height) wide, as VTK fits a scene, then a little closer."""
        angle = math.radians(VIEW_ANGLE)
        if aspect < 1.0:  # (VTK's fit: a vertical view angle narrows with a tall view)
            angle = 2.0 * math.atan(math.tan(angle / 2.0) * aspect)
        focal = ((low[0] + high[0]) / 2.0, (low[1] + high[1]) / 2.0, (low[2] + high[2]) / 2.0)
        distance = 0.5 * math.dist(low, high) / math.sin(angle / 2.0) / FIT_CLOSER
        return cls(focal, _cross(up, towards), up, towards, distance)

    def project(self, point: Vector, width: int, height: int, focal: float) -> tuple[float, float, float]:
        """Pixel column and row of ``point`` in a view ``width`` × ``height`` whose focal length is
        ``focal`` pixels (:func:`focal_length`), and its distance from the camera along the view."""
        d = [point[k] - self.focal[k] for k in range(3)]
        depth = self.distance - _dot(d, self.towards)
        scale = focal / max(depth, 1e-6)
        return width / 2.0 + scale * _dot(d, self.right), height / 2.0 - scale * _dot(d, self.up), depth


def focal_length(height: int) -> float:
    """Pixels: the focal length of a view ``height`` pixels tall (VTK's vertical view angle)."""
    return height / 2.0 / math.tan(math.radians(VIEW_ANGLE) / 2.0)


class Sketch(QWidget):
    """Where the 3D view will be: its background, and once given a trace (:meth:`draw`) the
    molecule from the view's first camera."""

    def __init__(self) -> None:
        super().__init__()
        self.trace: Trace | None = None
        self.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Expanding)  # (as the view's)

    def draw(self, trace: Trace) -> None:
        """Sketch ``trace``, painted at once (before the work that follows holds the event loop)."""
        self.trace = trace
        self.repaint()

    def paintEvent(self, event: QPaintEvent) -> None:
        width, height = self.width(), self.height()
        painter = QPainter(self)
        background = QLinearGradient(0, height, 0, 0)
        background.setColorAt(0.0, QColor(BACKGROUND[0]))
        background.setColorAt(1.0, QColor(BACKGROUND[1]))
        painter.fillRect(self.rect(), background)
        if self.trace is not None:
            self._draw_trace(painter, self.trace, width, height)
        painter.end()

    @staticmethod
    def _draw_trace(painter: QPainter, trace: Trace, width: int, height: int) -> None:
        """The trace's steps from the farthest band of depth to the nearest, as wide as the ribbon,
        fading with depth."""
        painter.setRenderHint(QPainter.RenderHint.Antialiasing)
        camera = trace.camera(width / max(height, 1))
        focal = focal_length(height)
        steps = []
        for run in trace.runs:
            projected = [camera.project(p, width, height, focal) for p in run.positions]
            for k in range(len(projected) - 1):
                (x0, y0, z0), (x1, y1, z1) = projected[k], projected[k + 1]
                kind = run.kinds[k] if run.kinds[k] == run.kinds[k + 1] else "C"
                steps.append(((z0 + z1) / 2.0, QLineF(x0, y0, x1, y1), kind))
        steps.sort(key=lambda step: -step[0])  # the farthest first: the nearer cover them
        near, far = steps[-1][0], steps[0][0]
        depth_of_band = (far - near) / DEPTH_BANDS
        bands: dict[tuple[int, str], list[QLineF]] = {}  # (band, kind): its steps, from the farthest band
        for depth, line, kind in steps:
            band = min(int((far - depth) / max(depth_of_band, 1e-9)), DEPTH_BANDS - 1)
            bands.setdefault((band, kind), []).append(line)
        pen = QPen(Qt.PenStyle.SolidLine)
        pen.setCapStyle(Qt.PenCapStyle.RoundCap)
        for (band, kind), lines in bands.items():
            depth = far - (band + 0.5) * depth_of_band
            pen.setColor(_mixed(COLOURS[kind], QColor(BACKGROUND[0]), FOG * (depth - near) / max(far - near, 1e-6)))
            pen.setWidthF(2.0 * HALF_WIDTHS[kind] * focal / max(depth, 1e-6))
            painter.setPen(pen)
            painter.drawLines(lines)


def _mixed(colour: RGB, background: QColor, share: float) -> QColor:
    """``colour`` with ``share`` (0 to 1) of ``background`` in it."""
    mix = (background.red(), background.green(), background.blue())
    return QColor(*(round((1.0 - share) * c + share * b) for c, b in zip(colour, mix)))


def _dot(a: Vector | list[float], b: Vector) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _cross(a: Vector, b: Vector) -> Vector:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
