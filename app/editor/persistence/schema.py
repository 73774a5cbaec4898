"""What each record kind of a journal or session holds (:mod:`app.editor.persistence.records`):
the types and ranges of its fields and the dtypes and shapes of its arrays, checked as a record is
decoded, before anything is built from it.

A record that breaks a rule is left out with the reason (:func:`problem`); fields not named here
are ignored (a newer writer's additions). What depends on the structure (a segment, a row or the
coordinates an edit was made on) is checked as the record is replayed
(:func:`app.editor.persistence.recording.replay`).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from core.protein.ribbon import RibbonKind

EDIT_ARRAYS = ("old_points", "new_points", "residues", "rows", "old_coords", "new_coords")
"""The arrays of one edit in a ``push`` record (``k.`` before each name for edit ``k`` of several)."""
MAX_TEXT = 4096
"""Characters a text field (a file name, a step's name) may hold."""
MAX_ITEMS = 100_000
"""Items a list field (segments of a step, layers, measurements, compared structures) may hold."""
MAX_INDEX = 2**31 - 1
MAX_COORDINATE = 1e6
"""Å: the largest camera coordinate taken (structures use PDB's own limit, 1e4 Å)."""
SELECTION = ("selected_residues", "selected_groups")
"""The arrays of a ``view`` record that hold the selection (newer than the format: optional)."""
COLOURINGS = ("secondary structure", "residue type", "chain", "rainbow, N to C", "B-factor")
"""The tube's colourings (:class:`app.editor.scene.molecule.Colouring`)."""

_REQUIRED = object()


class Invalid(ValueError):
    """A field or array that breaks its rule."""


def problem(kind: str, fields: dict, arrays: dict[str, np.ndarray]) -> str | None:
    """Why a record of ``kind`` with ``fields`` and ``arrays`` cannot be used, or None."""
    check = _KINDS.get(kind)
    if check is None:
        return f"unknown record kind {_shown(kind)}"
    try:
        check(fields, arrays)
    except Invalid as error:
        return f"{kind} record: {error}"
    return None


# ---------------------------------------------------------------------------- fields


def _shown(value: object) -> str:
    """``value`` as a message shows it (at most 40 characters)."""
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def _field(fields: dict, name: str, default: object) -> object:
    if name not in fields:
        if default is _REQUIRED:
            raise Invalid(f"no field {name!r}")
        return default
    return fields[name]


def integer(fields: dict, name: str, low: int = 0, high: int = MAX_INDEX, default: object = _REQUIRED) -> int:
    """Field ``name``, an integer in [low, high] (not a bool)."""
    value = _field(fields, name, default)
    if type(value) is not int or not low <= value <= high:
        raise Invalid(f"{name!r} must be an integer in [{low}, {high}]; got {_shown(value)}")
    return value


def number(fields: dict, name: str, low: float, high: float) -> float:
    """Field ``name``, a finite number in [low, high]."""
    value = _field(fields, name, _REQUIRED)
    if type(value) not in (int, float) or not (math.isfinite(value) and low <= value <= high):
        raise Invalid(f"{name!r} must be a number in [{low:g}, {high:g}]; got {_shown(value)}")
    return float(value)


def flag(fields: dict, name: str, default: object = _REQUIRED) -> bool:
    """Field ``name``, true or false."""
    value = _field(fields, name, default)
    if type(value) is not bool:
        raise Invalid(f"{name!r} must be true or false; got {_shown(value)}")
    return value


def text(fields: dict, name: str, default: object = _REQUIRED, *, choices: tuple[str, ...] = ()) -> str | None:
    """Field ``name``, a text of at most :data:`MAX_TEXT` characters without NUL (None where
    ``default`` is None and the field is null), one of ``choices`` if given."""
    value = _field(fields, name, default)
    if value is None and default is None:
        return None
    if type(value) is not str or len(value) > MAX_TEXT or "\0" in value or (choices and value not in choices):
        wanted = f"one of {', '.join(map(repr, choices))}" if choices else f"a text of at most {MAX_TEXT} characters"
        raise Invalid(f"{name!r} must be {wanted}; got {_shown(value)}")
    return value


def items(fields: dict, name: str, item: Callable[[object], bool], what: str, default: object = _REQUIRED) -> list:
    """Field ``name``, a list of at most :data:`MAX_ITEMS` items each ``item`` accepts (``what``)."""
    value = _field(fields, name, default)
    if type(value) is not list or len(value) > MAX_ITEMS or not all(item(v) for v in value):
        raise Invalid(f"{name!r} must be a list of {what}; got {_shown(value)}")
    return value


def _is_text(value: object) -> bool:
    return type(value) is str and len(value) <= MAX_TEXT and "\0" not in value


# ---------------------------------------------------------------------------- arrays


def array(arrays: dict[str, np.ndarray], name: str, kind: str, shape: tuple[int | None, ...]) -> np.ndarray:
    """Array ``name``: of ``kind`` ('f' finite floats, 'i' non-negative integers, 'u1' bytes) and
    ``shape`` (None: any length)."""
    if name not in arrays:
        raise Invalid(f"no array {name!r}")
    values = arrays[name]
    dtype = values.dtype
    if kind == "u1":
        ok = dtype == np.uint8
    elif kind == "i":
        ok = dtype.kind in "iu" and not (values.size and (values.min() < 0 or values.max() > MAX_INDEX))
    else:
        ok = dtype.kind == "f" and bool(np.isfinite(values).all())
    if not ok:
        wanted = {"u1": "bytes", "i": "indices (integers from 0)", "f": "finite numbers"}[kind]
        raise Invalid(f"array {name!r} must hold {wanted}")
    if len(values.shape) != len(shape) or any(n is not None and n != m for n, m in zip(shape, values.shape)):
        wanted = " x ".join("n" if n is None else str(n) for n in shape)
        raise Invalid(f"array {name!r} must be {wanted}; got {' x '.join(map(str, values.shape))}")
    return values


# ---------------------------------------------------------------------------- record kinds


def _header(fields: dict, arrays: dict[str, np.ndarray]) -> None:
    integer(fields, "version", 1)
    text(fields, "path")
    text(fields, "kind", choices=tuple(RibbonKind))
    integer(fields, "model", 1, default=1)
    array(arrays, "source", "u1", (None,))


def _push(fields: dict, arrays: dict[str, np.ndarray]) -> None:
    integer(fields, "at")
    text(fields, "text")
    if "segments" in fields:
        segments = items(fields, "segments", lambda v: type(v) is int and 0 <= v <= MAX_INDEX, "segment numbers")
        if not segments:
            raise Invalid("'segments' names no segment")
        prefixes = [f"{k}." for k in range(len(segments))]
    else:
        integer(fields, "segment")
        prefixes = [""]
    for prefix in prefixes:
        points = array(arrays, f"{prefix}old_points", "f", (None, 3))
        array(arrays, f"{prefix}new_points", "f", points.shape)
        array(arrays, f"{prefix}residues", "i", (None,))
        rows = array(arrays, f"{prefix}rows", "i", (None,))
        array(arrays, f"{prefix}old_coords", "f", (len(rows), 3))
        array(arrays, f"{prefix}new_coords", "f", (len(rows), 3))


def _base(fields: dict, arrays: dict[str, np.ndarray]) -> None:
    segments = integer(fields, "segments", 0, MAX_ITEMS)
    array(arrays, "coords", "f", (None, 3))
    for k in range(segments):
        array(arrays, f"points.{k}", "f", (None, 3))


def _state(fields: dict, arrays: dict[str, np.ndarray]) -> None:
    number(fields, "level", 0.0, 64.0)
    integer(fields, "segment")
    flag(fields, "multiresolution")


def _index(fields: dict, arrays: dict[str, np.ndarray]) -> None:
    _state(fields, arrays)
    integer(fields, "index")
    integer(fields, "clean", -1)
    text(fields, "path")
    text(fields, "save_path", None)


def _view(fields: dict, arrays: dict[str, np.ndarray]) -> None:
    items(fields, "layers", _is_text, "layer names")
    text(fields, "colouring", choices=COLOURINGS)
    flag(fields, "fat_helices")
    flag(fields, "helix_cylinders", False)
    items(fields, "measurements", lambda v: type(v) is dict, "measurements", [])
    camera = items(fields, "camera", lambda v: type(v) is list and len(v) == 3
                   and all(type(x) in (int, float) and abs(x) <= MAX_COORDINATE for x in v), "three coordinates")
    if len(camera) != 3 or np.allclose(camera[0], camera[1]) or not np.any(camera[2]):
        raise Invalid("'camera' must be a position, a focal point apart from it and a view-up direction")
    for name in SELECTION:  # (newer than the format: optional)
        if name in arrays:
            array(arrays, name, "i", (None,))
    compared = items(fields, "compared", lambda v: type(v) is dict, "compared structures")
    for k, entry in enumerate(compared):
        text(entry, "path")
        text(entry, "chain")
        flag(entry, "visible")
        array(arrays, f"compared_{k}", "u1", (None,))


_KINDS: dict[str, Callable[[dict, dict[str, np.ndarray]], None]] = {
    "header": _header, "base": _base, "push": _push, "index": _index, "state": _state, "view": _view}
