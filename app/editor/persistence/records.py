"""The record format of journals and session files (a document recorded and replayed:
:mod:`app.editor.persistence.recording`).

A file is :data:`MAGIC`, then records. A record is its payload length and CRC-32 (two
little-endian uint32), then the payload: a line of JSON (``record``, the kind of record,
its fields, and the names, dtypes and shapes of its arrays) followed by the arrays' raw
bytes. Arrays are written as they are in memory, so coordinates come back bit for bit. A
file cut off mid-record (a crash while writing) reads as the records before the cut; damaged
bytes in the middle are passed over to the next record whose CRC holds, and each record is
checked against its kind's rules (:mod:`app.editor.persistence.schema`) before it is used.

Kinds: ``header`` (format version, file name, ribbon kind, model, the file's bytes as read),
``base`` (where the undo history starts once its oldest steps were dropped: coordinates and
control points), ``push`` (an undo step pushed at a stack position: its text and the
:class:`~core.protein.model.Edit` of each segment it changed), ``index`` (the stack
position after a step, undo or redo, the clean position, the file names, the level,
segment and multiresolution switch), ``state`` (level, segment and multiresolution switch
alone) and ``view`` (session files: layers, camera, compared structures).
"""

from __future__ import annotations

import json
import math
import os
import re
import stat
import struct
import zlib
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from app.editor.history import Base
from app.editor.persistence import schema
from core.protein.input_files import input_limit, limit_text
from core.protein.model import Edit

MAGIC = b"\x89RWAVE\r\n"
"""The first bytes of a journal or session file."""
VERSION = 3
"""Format version written; files of a newer version are refused with a message. Version 2
added the model of the header (version 1 files hold model 1), version 3 steps of several
segments (a push record of one segment is written as before)."""
_FRAME = struct.Struct("<II")


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


@dataclass(frozen=True)
class Reading:
    """What a file's bytes hold (:func:`decode`)."""

    records: list[Record]
    """The records that can be used, in file order."""
    skipped: list[str] = field(default_factory=list)
    """What was passed over, for people: damaged bytes, records that break their rules."""
    cut_off: bool = False
    """Whether the file ends inside a record (a crash while writing)."""

    @property
    def damaged(self) -> bool:
        """Whether anything was passed over or cut off."""
        return bool(self.skipped) or self.cut_off


def decode(data: bytes) -> Reading:
    """The records of a file's bytes. Damaged bytes are passed over to the next record whose
    CRC holds, and a record that breaks its rules (:mod:`~app.editor.persistence.schema`) is
    left out; both are named in :attr:`Reading.skipped`. Raises RecordError for a file that is
    not one of ours, of a newer version, or whose header is damaged."""
    if not data.startswith(MAGIC):
        raise RecordError("not a ribbonwave journal or session file")
    found, skipped, offset, cut_off = [], [], len(MAGIC), False
    while offset < len(data):
        end, record, wrong = _record_at(data, offset)
        if end is None:
            end = _next_frame(data, offset + 1)
            if end is None:
                cut_off = True
                break
            skipped.append(f"{end - offset} damaged bytes at byte {offset}")
        elif wrong is None:
            found.append(record)
        else:
            if not found and record is not None and record.kind == "header":
                _refuse_newer(record.fields)
            skipped.append(wrong)
        offset = end
    if found and found[0].kind == "header":
        _refuse_newer(found[0].fields)
    if not found and cut_off and not skipped:
        return Reading([], [], True)  # (cut inside the header: nothing was written yet)
    if not found or found[0].kind != "header":
        reason = skipped[0] if skipped else "no header record"
        raise RecordError(f"its header is damaged or missing ({reason}): not readable as a ribbonwave journal "
                          "or session file")
    return Reading(found, skipped, cut_off)


def _refuse_newer(fields: dict) -> None:
    version = fields.get("version")
    if type(version) is int and version > VERSION:
        raise RecordError(f"written by a newer ribbonwave (format {version}; this one reads format {VERSION})")


def _record_at(data: bytes, offset: int) -> tuple[int | None, Record | None, str | None]:
    """The end of the record framed at ``offset`` (None if it is incomplete or its CRC fails),
    the record, and why it cannot be used (None if it can)."""
    if offset + _FRAME.size > len(data):
        return None, None, None
    length, crc = _FRAME.unpack_from(data, offset)
    end = offset + _FRAME.size + length
    payload = data[offset + _FRAME.size : end]
    if len(payload) != length or zlib.crc32(payload) != crc:
        return None, None, None
    line, _, raw = payload.partition(b"\n")
    try:
        meta = json.loads(line)
    except (ValueError, RecursionError):
        return end, None, "a record whose fields are not JSON"
    if type(meta) is not dict or type(meta.get("record")) is not str:
        return end, None, "a record of no kind"
    kind = meta.pop("record")
    arrays, wrong = _arrays(meta.pop("arrays", []), raw)
    wrong = schema.problem(kind, meta, arrays) if wrong is None else f"{kind[:40]} record: {wrong}"
    return end, Record(kind, meta, arrays), wrong


_DTYPE = re.compile(r"[<>|=]?[fiub][1248]")


def _arrays(names: object, raw: bytes) -> tuple[dict[str, np.ndarray], str | None]:
    """The arrays a record's JSON line names (``[name, dtype, shape]`` each) in the bytes
    ``raw`` after it, and why they cannot be read (None if they can)."""
    arrays, start = {}, 0
    if type(names) is not list:
        return {}, "its 'arrays' is not a list"
    for entry in names:
        if not (type(entry) is list and len(entry) == 3 and type(entry[0]) is str and type(entry[1]) is str
                and _DTYPE.fullmatch(entry[1]) and type(entry[2]) is list and len(entry[2]) <= 4
                and all(type(n) is int and n >= 0 for n in entry[2])):
            return {}, f"array entry {str(entry)[:40]} is not [name, dtype, shape]"
        name, dtype, shape = entry[0], np.dtype(entry[1]), entry[2]
        size = math.prod(shape) * dtype.itemsize
        if start + size > len(raw):
            return {}, f"array {name[:40]!r} runs past the record"
        arrays[name] = np.frombuffer(raw, dtype=dtype, count=math.prod(shape), offset=start).reshape(shape).copy()
        start += size
    return arrays, None


def _next_frame(data: bytes, start: int) -> int | None:
    """The offset of the first record at or after ``start`` whose CRC holds (a record's
    payload starts with its JSON object), or None."""
    at = data.find(b'{"', start + _FRAME.size)
    while at >= 0:
        if _record_at(data, at - _FRAME.size)[0] is not None:
            return at - _FRAME.size
        at = data.find(b'{"', at + 1)
    return None


def header(path: Path, kind: str, source: bytes, model: int) -> Record:
    """The first record: the file as read, its name, the ribbon kind and the model (from 1) edited."""
    return Record("header", {"version": VERSION, "path": str(path), "kind": kind, "model": model},
                  {"source": np.frombuffer(source, dtype=np.uint8)})


def base(start: Base) -> Record:
    """Where the undo history starts once its oldest steps were dropped: the coordinates and each
    segment's finest control points."""
    return Record("base", {"segments": len(start.points)},
                  {"coords": start.coords, **{f"points.{k}": points for k, points in enumerate(start.points)}})


def base_of(record: Record) -> Base:
    """The :class:`~app.editor.history.Base` of a ``base`` record."""
    return Base(record.arrays["coords"].astype(np.float64),
                [record.arrays[f"points.{k}"].astype(np.float64) for k in range(record.fields["segments"])])


def model_of(fields: dict) -> int:
    """The model of a ``header`` record's fields (1 for files written before models were recorded)."""
    return fields.get("model", 1)


def push(at: int, text: str, edits: Sequence[Edit]) -> Record:
    """An undo step of ``edits`` named ``text`` pushed with the stack at position ``at``."""
    if len(edits) == 1:
        edit = edits[0]
        return Record("push", {"at": at, "text": text, "segment": edit.segment},
                      {name: getattr(edit, name) for name in schema.EDIT_ARRAYS})
    return Record("push", {"at": at, "text": text, "segments": [edit.segment for edit in edits]},
                  {f"{k}.{name}": getattr(edit, name) for k, edit in enumerate(edits) for name in schema.EDIT_ARRAYS})


def edits_of(record: Record) -> list[Edit]:
    """The edits of a ``push`` record, their indices as int64 and coordinates as float64 (as
    this machine holds them: a file's other integer or float types convert exactly)."""
    fields, arrays = record.fields, record.arrays
    prefixes = [f"{k}." for k in range(len(fields["segments"]))] if "segments" in fields else [""]
    segments = fields["segments"] if "segments" in fields else [fields["segment"]]
    return [Edit(segment, *(arrays[prefix + name].astype(np.int64 if name in ("residues", "rows") else np.float64)
                            for name in schema.EDIT_ARRAYS))
            for prefix, segment in zip(prefixes, segments, strict=True)]


def source_of(record: Record) -> bytes:
    """The file's bytes of a ``header`` record."""
    return record.arrays["source"].tobytes()


def read(path: Path) -> Reading:
    """The records of the file at ``path`` (see :func:`decode`); raises OSError, or RecordError
    for anything but a regular file (a FIFO or device is never read) or one over the input limit."""
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    with os.fdopen(fd, "rb") as file:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            raise RecordError("not a regular file (a device, FIFO or socket is not read)")
        if info.st_size > input_limit():
            raise RecordError(f"{info.st_size / 2**20:.0f} MiB is more than the input limit ({limit_text()})")
        return decode(file.read())
