"""A structure file's bytes, read within the input limit, gunzipped and decoded (the standard
library alone: the window's sketch of the molecule reads files with it before numpy loads)."""

from __future__ import annotations

import gzip
import io
import os
import stat
import zlib
from pathlib import Path

MAX_INPUT_MB = 4096
"""MiB a structure file may hold, decompressed (the largest PDB entries hold a few hundred)."""
LIMIT_VARIABLE = "RIBBONWAVE_MAX_INPUT_MB"
GUNZIP_CHUNK = 2**24
"""Bytes decompressed at a time."""


class StructureError(ValueError):
    """A file that cannot be used as a protein structure, or a bad argument to a writer."""


def read_bytes(path: str | os.PathLike[str]) -> bytes:
    """The content of a structure file as stored (gzipped or not); raises StructureError for
    anything but a regular file (a device or FIFO is never read) or one over :func:`input_limit`."""
    path = Path(path)
    try:
        info = path.stat()
    except FileNotFoundError:
        raise StructureError(f"{path}: no such file") from None
    except OSError as exc:
        raise StructureError(f"{path}: cannot read ({exc.strerror})") from None
    if stat.S_ISDIR(info.st_mode):
        raise StructureError(f"{path}: is a directory, not a structure file")
    if not stat.S_ISREG(info.st_mode):
        raise StructureError(f"{path}: not a regular file (a device, FIFO or socket is not read)")
    if info.st_size > input_limit():
        raise StructureError(f"{path}: {info.st_size / 2**20:.0f} MiB is more than the input limit "
                             f"({limit_text()})")
    try:
        return path.read_bytes()
    except OSError as exc:
        raise StructureError(f"{path}: cannot read ({exc.strerror})") from None


def input_limit() -> int:
    """Bytes a structure file may hold, decompressed: ``$RIBBONWAVE_MAX_INPUT_MB`` MiB
    (default :data:`MAX_INPUT_MB`)."""
    try:
        return int(float(os.environ.get(LIMIT_VARIABLE, MAX_INPUT_MB)) * 2**20)
    except ValueError:
        raise StructureError(f"${LIMIT_VARIABLE} must be a number of MiB; got "
                             f"{os.environ[LIMIT_VARIABLE]!r}") from None


def limit_text() -> str:
    """The input limit and how to raise it, for messages."""
    return f"{input_limit() / 2**20:g} MiB; set ${LIMIT_VARIABLE} to raise it"


def text_of(path: Path, data: bytes) -> tuple[str, str]:
    """File content as text, gunzipped when it starts with the gzip magic bytes, and the
    encoding that gives back its bytes: UTF-8, else Latin-1 (every byte is a character)."""
    if data[:2] == b"\x1f\x8b":
        limit = input_limit()
        chunks, size = [], 0
        try:
            with gzip.GzipFile(fileobj=io.BytesIO(data)) as stream:
                while chunk := stream.read(GUNZIP_CHUNK):  # (read(limit) would allocate the whole limit)
                    size += len(chunk)
                    if size > limit:  # never more than the limit in memory
                        raise StructureError(f"{path}: decompresses to more than the input limit ({limit_text()})")
                    chunks.append(chunk)
        except (OSError, EOFError, zlib.error) as exc:
            raise StructureError(f"{path}: corrupt gzip file ({exc})") from None
        data = b"".join(chunks)
    if not data.strip():
        raise StructureError(f"{path}: empty file")
    try:
        return data.decode("utf-8"), "utf-8"
    except UnicodeDecodeError:
        return data.decode("latin-1"), "latin-1"


def looks_like_mmcif(text: str) -> bool:
    """True when the first line that is neither blank nor a comment starts a CIF block."""
    for line in text.splitlines():
        stripped = line.strip()
        if stripped and not stripped.startswith("#"):
            return stripped.lower().startswith("data_")
    return False
