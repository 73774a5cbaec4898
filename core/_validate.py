"""Argument checks shared by the public entry points of core/.

Every check raises ``ValueError`` with a message that names the argument and says what
was expected and what was given.
"""

from __future__ import annotations

import numpy as np


def finite_array(name: str, value: object, *, ndim: tuple[int, ...] = (1, 2)) -> np.ndarray:
    """Return ``value`` as a float64 array after checking its rank and finiteness."""
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be a numeric array: {exc}") from None
    if array.ndim not in ndim:
        wanted = " or ".join(f"{d}-D" for d in ndim)
        raise ValueError(f"{name} must be {wanted}; got shape {array.shape}")
    if not np.all(np.isfinite(array)):
        bad = int(np.count_nonzero(~np.isfinite(array)))
        raise ValueError(f"{name} contains {bad} non-finite value(s) (NaN or inf)")
    return array


def level_of_size(name: str, n_points: int, *, closed: bool) -> int:
    """Finest level m of a control polygon with ``n_points`` rows.

    Open curves need ``2**m + 3`` points (m >= 0), closed curves ``2**m`` (m >= 0).
    """
    offset = 0 if closed else 3
    size = n_points - offset
    if size < 1 or size & (size - 1):
        examples = ", ".join(str(2**m + offset) for m in range(5))
        kind = "2**m" if closed else "2**m + 3"
        raise ValueError(
            f"{name} must have {kind} rows ({examples}, ...) for a "
            f"{'closed' if closed else 'open'} curve; got {n_points}"
        )
    return size.bit_length() - 1


def level_in_range(name: str, level: float, low: float, high: float) -> float:
    """Check that ``low <= level <= high`` and return it as a float."""
    level = float(level)
    if not np.isfinite(level) or not low <= level <= high:
        raise ValueError(f"{name} must lie in [{low:g}, {high:g}]; got {level:g}")
    return level


def integer_level(name: str, level: object, low: int, high: int) -> int:
    """Check an integer level in ``[low, high]``."""
    if isinstance(level, bool) or not isinstance(level, (int, np.integer)):
        raise ValueError(f"{name} must be an integer level; got {level!r}")
    if not low <= level <= high:
        raise ValueError(f"{name} must lie in [{low}, {high}]; got {level}")
    return int(level)
