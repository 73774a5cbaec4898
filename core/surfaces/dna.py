"""An ideal B-DNA duplex from standard fibre geometry (Arnott and Hukins, 1972).

Atoms of one nucleotide are given in cylindrical coordinates ``(r Å, θ°, z Å)`` about the
helix axis; nucleotide ``n`` of strand I is turned by ``36° n`` and raised by ``3.38 Å n``
(10 base pairs per right-handed turn), and its partner on strand II is related by the
dyad ``(r, θ, z) -> (r, −θ, −z)``. Hydrogens are not modelled.
"""

from __future__ import annotations

import numpy as np

from core.protein.structure import AtomTable

RISE = 3.38
"""Rise per base pair, Å."""

TWIST = 36.0
"""Twist per base pair, degrees."""

# Arnott & Hukins (1972), Biochem. Biophys. Res. Commun. 47, 1504: B-DNA, modern atom names.
_BACKBONE = {
    "OP1": (8.75, 97.4, 3.63), "OP2": (10.20, 91.1, 1.86), "O3'": (8.82, 103.3, 1.29),
    "P": (8.91, 95.2, 2.08), "O5'": (7.73, 88.0, 1.83), "C5'": (7.70, 79.8, 2.77),
    "O4'": (6.22, 66.0, 1.83), "C4'": (7.59, 69.9, 2.04), "C3'": (8.20, 69.9, 0.64),
    "C2'": (7.04, 73.2, -0.24), "C1'": (5.86, 67.4, 0.47),
}  # fmt: skip
_BASES = {
    "A": {"N9": (4.63, 76.6, 0.42), "C8": (4.84, 93.0, 0.50), "N7": (3.95, 105.4, 0.43),
          "C5": (2.74, 94.0, 0.28), "N6": (1.83, 154.0, 0.14), "C6": (1.41, 107.2, 0.15),
          "N1": (0.86, 40.1, 0.03), "C2": (2.17, 30.6, 0.04), "N3": (3.24, 47.0, 0.16),
          "C4": (3.33, 70.5, 0.28)},
    "G": {"N9": (4.63, 76.6, 0.42), "C8": (4.82, 93.2, 0.50), "N7": (3.92, 105.7, 0.42),
          "C5": (2.70, 94.0, 0.28), "O6": (1.71, 154.6, 0.13), "C6": (1.39, 109.3, 0.15),
          "N1": (0.92, 37.9, 0.03), "N2": (3.01, 4.2, -0.10), "C2": (2.28, 28.7, 0.03),
          "N3": (3.29, 46.7, 0.16), "C4": (3.33, 70.3, 0.28)},
    "C": {"N1": (4.63, 76.6, 0.42), "C6": (4.99, 92.2, 0.52), "C5": (4.35, 107.0, 0.47),
          "N4": (2.76, 136.6, 0.27), "C4": (2.94, 110.0, 0.32), "N3": (2.31, 83.9, 0.22),
          "O2": (3.69, 47.9, 0.18), "C2": (3.40, 67.4, 0.27)},
    "T": {"N1": (4.63, 76.6, 0.42), "C6": (5.01, 92.3, 0.52), "C7": (5.40, 119.8, 0.58),
          "C5": (4.38, 106.9, 0.47), "O4": (2.82, 136.3, 0.27), "C4": (2.98, 111.9, 0.32),
          "N3": (2.36, 85.2, 0.23), "O2": (3.64, 47.8, 0.18), "C2": (3.42, 67.3, 0.27)},
}  # fmt: skip
_PARTNER = {"A": "T", "T": "A", "G": "C", "C": "G"}


def ideal_bdna(sequence: str) -> AtomTable:
    """Atoms of a B-DNA duplex of ``sequence`` (strand I, 5'→3', letters ACGT) and its
    complement (chain B), the helix axis along z from the origin."""
    sequence = sequence.upper()
    if not sequence or set(sequence) - set(_PARTNER):
        raise ValueError(f"sequence must be a non-empty string of A, C, G, T; got {sequence!r}")
    rows = []  # (chain, resseq, resname, atom name, r, theta, z)
    n = len(sequence)
    for i, base in enumerate(sequence):
        for chain, letter, sign, number in (("A", base, 1, i + 1), ("B", _PARTNER[base], -1, 2 * n - i)):
            for name, (r, theta, z) in (_BACKBONE | _BASES[letter]).items():
                rows.append((chain, number, "D" + letter, name, r, sign * theta + TWIST * i, sign * z + RISE * i))
    rows.sort(key=lambda row: (row[0], row[1]))
    chain, resseq, resname, name, r, theta, z = (np.array(column) for column in zip(*rows, strict=True))
    angle = np.radians(theta.astype(np.float64))
    coords = np.stack([r * np.cos(angle), r * np.sin(angle), z], axis=1).astype(np.float64)
    first = np.concatenate([[True], (chain[1:] != chain[:-1]) | (resseq[1:] != resseq[:-1])])
    return AtomTable(
        entry_id=f"ideal B-DNA {sequence}",
        coords=_read_only(coords),
        name=_read_only(name.astype(str)),
        element=_read_only(np.array([atom[0] for atom in name])),
        altloc=_read_only(np.full(len(name), "")),
        resname=_read_only(resname.astype(str)),
        chain=_read_only(chain.astype(str)),
        resseq=_read_only(resseq.astype(np.int64)),
        residue=_read_only(np.cumsum(first) - 1),
        b_factor=_read_only(np.zeros(len(name))),
        occupancy=_read_only(np.ones(len(name))),
        category=_read_only(np.full(len(name), "nucleic")),
    )


def _read_only(array: np.ndarray) -> np.ndarray:
    array = np.ascontiguousarray(array)
    array.flags.writeable = False
    return array
