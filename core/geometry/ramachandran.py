"""Ramachandran regions: coarse favoured/allowed maps of (φ, ψ) for general, glycine and
proline residues, and the nearest allowed point of an outlier."""

from __future__ import annotations

import functools

import numpy as np

# The grids: 18 x 18 cells of 20°, φ from -180 (left) to 180, ψ from 180 (top) to -180.
# '#' favoured, '+' allowed, '.' outlier. Favoured: the densest cells holding 98% of the
# (φ, ψ) of 25,000 residues with backbone B < 30 Å² in the 100-odd X-ray entries at
# <= 2.0 Å of a 229-entry diverse set (glycine symmetrised under (φ, ψ) -> (-φ, -ψ));
# allowed: favoured widened by one cell, roughly where Lovell et al. (2003) draw the
# allowed contour. Outside allowed lie 0.4% of those residues (0.9% of all 65,000).
_GRIDS = {
    "general": """
        ######++.........+
        #######+.........+
        #######+.........+
        +#####++.........+
        +####++...........
        ++#+#+....++++....
        +##+#+....+##+....
        ++###++...+##+....
        .+####+...++#+....
        .+####++...+++....
        .+#####+..........
        .++####+..........
        ..++++++..........
        ..................
        ..................
        ..................
        ++++++............
        +####++..........+""",
    "glycine": """
        ######++...+######
        #######+...++#####
        ++#####+....+##+++
        .+#+#+++....+##+..
        .+++++.....+++++..
        ...+++....++#+++..
        .+++#+....+####+..
        .+###++...+####++.
        .+####++..+#####+.
        .+#####+..++####+.
        .++####+...++###+.
        ..+####+....+#+++.
        ..+++#++....+++...
        ..+++++.....+++++.
        ..+##+....+++#+#+.
        +++##+....+#####++
        #####++...+#######
        ######+...++######""",
    "proline": """
        ...+###+..........
        ...+###+..........
        ..++###+..........
        ..+####+..........
        ..++##++..........
        ...+##+...........
        ...+##+...........
        ..+++#+...........
        ..+##+++..........
        ..++###+..........
        ...+###+..........
        ...++##+..........
        ....++++..........
        ..................
        ..................
        ..................
        ...+++............
        ...+#+++..........""",
}
RAMACHANDRAN_CLASSES = ("general", "glycine", "proline")
FAVOURED, ALLOWED, OUTLIER = 0, 1, 2
RAMACHANDRAN = np.stack([
    np.array([["#+.".index(ch) for ch in line.strip()] for line in _GRIDS[name].strip().splitlines()], dtype=np.int8)
    for name in RAMACHANDRAN_CLASSES
])
"""(3, 18, 18) region codes (FAVOURED, ALLOWED, OUTLIER) per class, ψ row (from +180 down),
φ column (from -180); see the module source for the maps and how they were made."""


def ramachandran_region(phi: np.ndarray, psi: np.ndarray, kind: np.ndarray) -> np.ndarray:
    """Region code (FAVOURED, ALLOWED, OUTLIER) of (φ, ψ) in degrees for class indices ``kind``
    (0 general, 1 glycine, 2 proline; see :data:`RAMACHANDRAN_CLASSES`)."""
    column = np.clip(((np.asarray(phi) + 180.0) // 20).astype(np.int64), 0, 17)
    row = np.clip(((180.0 - np.asarray(psi)) // 20).astype(np.int64), 0, 17)
    return RAMACHANDRAN[np.asarray(kind), row, column]


def nearest_allowed(phi: np.ndarray, psi: np.ndarray, kind: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The allowed (φ, ψ) nearest to each (φ, ψ) in degrees, to 2° (itself where allowed;
    the values may lie beyond ±180 on the other side of the wrap)."""
    column = ((np.asarray(phi) + 180.0) // 2).astype(np.int64) % 180
    row = ((180.0 - np.asarray(psi)) // 2).astype(np.int64) % 180
    target = _nearest_allowed_cells()[np.asarray(kind), row, column]
    allowed = ramachandran_region(phi, psi, kind) != OUTLIER
    return np.where(allowed, phi, target[..., 0]), np.where(allowed, psi, target[..., 1])


@functools.lru_cache(maxsize=1)
def _nearest_allowed_cells() -> np.ndarray:
    """(classes, 180, 180, 2): per class and 2° cell (ψ row from +180 down, φ column from
    -180), the (φ, ψ) centre of the nearest allowed 2° cell, across the periodic wrap."""
    from scipy import ndimage  # only regularization needs it: validating (and the editor's start) does not

    fine = np.repeat(np.repeat(RAMACHANDRAN == OUTLIER, 10, axis=1), 10, axis=2)
    out = np.empty((len(fine), 180, 180, 2))
    for k, outlier in enumerate(fine):
        _, (row, column) = ndimage.distance_transform_edt(np.tile(outlier, (3, 3)), return_indices=True)
        row, column = row[180:360, 180:360] - 180, column[180:360, 180:360] - 180
        out[k, ..., 0] = -180.0 + 2 * column + 1
        out[k, ..., 1] = 180.0 - 2 * row - 1
    return out
