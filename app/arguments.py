"""What every command checks of its arguments before any work starts: numbers within their sane
ranges (a value outside is a usage error, exit status 2, whose message gives the range), an
output file it can write (:func:`writable_output`), and a file named with its chain
(:func:`file_and_chain`)."""

from __future__ import annotations

import argparse
import math
import os
from collections.abc import Callable
from pathlib import Path

from app.errors import InputError

LEVEL = (0.0, 30.0)
"""Carson levels: log2 of a segment's residues stays far below 30."""
IMAGE_SIDE = (1, 16384)
"""Pixels of an exported image's width or height."""
SUPERSAMPLING = (1, 2, 4)
"""Factors an exported image may be rendered larger by and averaged down."""


def bounded(kind: type, low: float, high: float) -> Callable[[str], float | int]:
    """An argparse type: a finite ``kind`` (int or float) in ``[low, high]``."""
    def parse(text: str) -> float | int:
        try:
            value = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a {'whole ' if kind is int else ''}number; got {text!r}") \
                from None
        if not (math.isfinite(value) and low <= value <= high):
            raise argparse.ArgumentTypeError(f"must lie in [{low:g}, {high:g}]; got {text}")
        return value
    parse.__name__ = kind.__name__  # argparse names the type in its messages
    return parse


def bounded_list(low: int, high: int) -> Callable[[str], tuple[int, ...]]:
    """An argparse type: whole numbers in ``[low, high]`` separated by commas."""
    def parse(text: str) -> tuple[int, ...]:
        try:
            values = tuple(int(part) for part in text.split(","))
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected whole numbers separated by commas; got {text!r}") from None
        if not all(low <= v <= high for v in values):
            raise argparse.ArgumentTypeError(f"numbers must lie in [{low}, {high}]; got {text!r}")
        return values
    parse.__name__ = "list"
    return parse


def writable_output(path: Path, overwrite: bool) -> None:
    """Refuse, before any work, an output file a command could not write at the end: a folder,
    a file that exists (unless ``overwrite``), or a missing or read-only folder (:class:`InputError`)."""
    if path.is_dir():
        raise InputError(f"{path}: is a folder")
    if (path.exists() or path.is_symlink()) and not overwrite:
        raise InputError(f"{path}: refusing to overwrite an existing file (use --overwrite)")
    if not path.parent.is_dir():
        raise InputError(f"{path}: no such folder {path.parent}")
    if not os.access(path.parent, os.W_OK | os.X_OK):
        raise InputError(f"{path.parent}: cannot write in the folder (permission denied)")


def file_and_chain(spec: str) -> tuple[Path, str | None]:
    """``FILE`` or ``FILE:CHAIN``: a chain only where ``spec`` names no file and ``FILE`` does (a
    file whose name has a colon is taken whole)."""
    path = Path(spec)
    if not path.exists() and ":" in spec:
        name, chain = spec.rsplit(":", 1)
        if chain and Path(name).is_file():
            return Path(name), chain
    return path, None


def chain_hint(path: Path) -> str:
    """What to add to "no such file" where ``path`` is ``FILE:CHAIN`` given to a command that
    takes a file alone ('' for any other path)."""
    named, chain = file_and_chain(str(path))
    return "" if chain is None else (f" (this command takes no chain after a colon: give {named}, and see --help "
                                     "for a chain option)")
