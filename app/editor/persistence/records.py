"""The record format of journals and session files (a document recorded and replayed:
:mod:`app.editor.persistence.recording`).

A file is :data:`MAGIC`, then records. A record is its payload length and CRC-32 (two
little-endian uint32), then the payload: a line of JSON (``record``, the kind of record,
its fields, and the names, dtypes and shapes of its arrays) followed by the arrays' raw
bytes. Arrays are
written as they are in memory, so coordinates come back bit for bit. A file cut off
mid-record (a crash while writing) reads as the records before the damage.

Kinds: ``header`` (format version, file name, ribbon kind, model, the file's bytes as read),
``push`` (an undo step pushed at a stack position: its text and the
:class:`~core.protein.model.Edit` of each segment it changed), ``index`` (the stack
position after a step, undo or redo, the clean position, the file names, the level,
segment and multiresolution switch), ``state`` (level, segment and multiresolution switch
alone) and ``view`` (session files: layers, camera, compared structures).
"""

from __future__ import annotations

import json
import struct
import zlib
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from core.protein.model import Edit

MAGIC = b"\x89RWAVE\r\n"
"""The first bytes of a journal or session file."""
VERSION = 3
"""Format version written; files of a newer version are refused with a message. Version 2
added the model of the header (version 1 files hold model 1), version 3 steps of several
segments (a push record of one segment is written as before)."""
_FRAME = struct.Struct("<II")
_EDIT_ARRAYS = ("old_points", "new_points", "residues", "rows", "old_coords", "new_coords")


class RecordError(ValueError):
    """A file that is not a ribbonwave journal or session, or one of a newer version."""


@dataclass(frozen=True)
class Record:
    """One record: its kind, JSON fields and named arrays."""

    kind: str
    fields: dict
    arrays: dict[str, np.ndarray] = field(default_factory=dict)


def encode(record: Record) -> bytes:
    """The bytes of ``record``, framed."""
    arrays = {name: np.ascontiguousarray(a) for name, a in record.arrays.items()}
    meta = {**record.fields, "record": record.kind,
            "arrays": [[name, a.dtype.str, list(a.shape)] for name, a in arrays.items()]}
    payload = b"".join([json.dumps(meta, separators=(",", ":")).encode(), b"\n", *(a.tobytes() for a in arrays.values())])
    return _FRAME.pack(len(payload), zlib.crc32(payload)) + payload


def decode(data: bytes) -> tuple[list[Record], bool]:
    """The records of a file's bytes and whether it was damaged (cut off or corrupt after
    the last record returned). Raises RecordError for a file that is not one of ours."""
    if not data.startswith(MAGIC):
        raise RecordError("not a ribbonwave journal or session file")
    records, offset, damaged = [], len(MAGIC), False
    while offset < len(data) and not damaged:
        record, offset = _record_at(data, offset)
        damaged = record is None
        records += [] if damaged else [record]
    if records and records[0].kind == "header" and records[0].fields.get("version", 0) > VERSION:
        raise RecordError(f"written by a newer ribbonwave (format {records[0].fields['version']}; "
                          f"this one reads format {VERSION})")
    if (records[0].kind != "header") if records else not damaged:  # (cut inside the header: nothing to read)
        raise RecordError("no header record: not a ribbonwave journal or session file")
    return records, damaged


def _record_at(data: bytes, offset: int) -> tuple[Record | None, int]:
    """The record framed at ``offset`` and the offset after it; None if it is incomplete or corrupt."""
    if offset + _FRAME.size > len(data):
        return None, offset
    length, crc = _FRAME.unpack_from(data, offset)
    payload = data[offset + _FRAME.size : offset + _FRAME.size + length]
    if len(payload) != length or zlib.crc32(payload) != crc:
        return None, offset
    line, _, raw = payload.partition(b"\n")
    try:
        meta = json.loads(line)
        arrays, start = {}, 0
        for name, dtype, shape in meta.pop("arrays"):
            array = np.frombuffer(raw, dtype=np.dtype(dtype), count=int(np.prod(shape)), offset=start).reshape(shape)
            arrays[name] = array.copy()
            start += array.nbytes
        kind = meta.pop("record")
    except (ValueError, KeyError, TypeError):
        return None, offset
    return Record(kind, meta, arrays), offset + _FRAME.size + length


def header(path: Path, kind: str, source: bytes, model: int) -> Record:
    """The first record: the file as read, its name, the ribbon kind and the model (from 1) edited."""
    return Record("header", {"version": VERSION, "path": str(path), "kind": kind, "model": model},
                  {"source": np.frombuffer(source, dtype=np.uint8)})


def model_of(fields: dict) -> int:
    """The model of a ``header`` record's fields (1 for files written before models were recorded)."""
    return fields.get("model", 1)


def push(at: int, text: str, edits: Sequence[Edit]) -> Record:
    """An undo step of ``edits`` named ``text`` pushed with the stack at position ``at``."""
    if len(edits) == 1:
        edit = edits[0]
        return Record("push", {"at": at, "text": text, "segment": edit.segment},
                      {name: getattr(edit, name) for name in _EDIT_ARRAYS})
    return Record("push", {"at": at, "text": text, "segments": [edit.segment for edit in edits]},
                  {f"{k}.{name}": getattr(edit, name) for k, edit in enumerate(edits) for name in _EDIT_ARRAYS})


def edits_of(record: Record) -> list[Edit]:
    """The edits of a ``push`` record."""
    fields, arrays = record.fields, record.arrays
    if "segments" not in fields:
        return [Edit(fields["segment"], *(arrays[name] for name in _EDIT_ARRAYS))]
    return [Edit(segment, *(arrays[f"{k}.{name}"] for name in _EDIT_ARRAYS))
            for k, segment in enumerate(fields["segments"])]


def source_of(record: Record) -> bytes:
    """The file's bytes of a ``header`` record."""
    return record.arrays["source"].tobytes()


def read(path: Path) -> tuple[list[Record], bool]:
    """The records of the file at ``path`` and whether it was damaged (see :func:`decode`);
    raises OSError or RecordError."""
    return decode(Path(path).read_bytes())
