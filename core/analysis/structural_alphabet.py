"""A chain as two strings: its residues' 3Di states and amino acids, from Cα alone.

Foldseek's 3Di alphabet (van Kempen et al. 2024, Nat. Biotechnol. 42:243) names each residue
by the geometry of its backbone and of its nearest residue in space, one of 20 states; two
chains of one fold share long stretches of states where their sequences have drifted apart.
:mod:`mini3di` (a NumPy port of Foldseek's encoder, its trained weights) encodes them from the
N, Cα and Cβ of each residue. Fold search must also read Cα-only chains (SCOP's benchmark,
old and coarse models), so :func:`backbone_from_ca` places N and Cβ where they lie on average
in the frame of the residue's Cα and its two neighbours, as a linear function of the Cα
angle: on the 255 entries of the shared set, 0.18 Å rms for N and 0.28 Å for Cβ, and 88% of
the residues get the state their full backbone gives.

The substitution scores (half bits) are ours, learnt by ``scripts/train_fold_scores.py`` from
the structural alignments of similar chains of other proteins (never the labelled SCOP sets):
:data:`STATE_SCORES` for 3Di, with NCBI's BLOSUM62 for the amino acids (:data:`AMINO_ACID_SCORES`).
"""

from __future__ import annotations

from functools import cache

import numpy as np

STATES = "ACDEFGHIKLMNPQRSTVWY"
"""The 20 3Di states, in mini3di's order."""
AMINO_ACIDS = "ARNDCQEGHILKMFPSTWYVX"
"""One-letter codes, in BLOSUM62's order; X for any other."""
N_OFFSETS = np.array([[-1.0631, -0.9301, 0.3375], [0.5483, -0.8389, 0.0367], [0.3561, -0.5724, 0.0087]])
"""N from Cα: rows multiply 1, cos θ and cos² θ (θ the Cα angle at the residue); columns are
the axes of the residue's frame (:func:`backbone_from_ca`), Å."""
CB_OFFSETS = np.array([[0.2257, 0.9766, 1.1363], [0.5096, -1.1676, 1.4106], [0.4988, -0.9244, 1.1059]])
"""Cβ from Cα, as :data:`N_OFFSETS`."""


def backbone_from_ca(ca: np.ndarray, n_offsets: np.ndarray = N_OFFSETS, cb_offsets: np.ndarray = CB_OFFSETS
                     ) -> tuple[np.ndarray, np.ndarray]:
    """The likeliest N and Cβ (n, 3 each, Å) of a chain of Cα ``ca`` (n >= 3, 3).

    Each residue's frame has its first axis from the previous Cα to the next, its second along
    the outward bisector of the Cα angle, its third their cross product; the offsets are
    linear in the angle's cosine and its square (the first and last residue take their
    neighbour's frame)."""
    ca = np.asarray(ca, dtype=np.float64)
    frames, powers = residue_frames(ca)
    return (ca + np.einsum("nji,nj->ni", frames, powers @ n_offsets),
            ca + np.einsum("nji,nj->ni", frames, powers @ cb_offsets))


def residue_frames(ca: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(n, 3, 3) each residue's frame of :func:`backbone_from_ca` (rows: axes) and (n, 3) the
    powers 1, cos θ, cos² θ of its Cα angle; ``ca`` (n >= 3, 3) float64."""
    before, after = ca[1:-1] - ca[:-2], ca[2:] - ca[1:-1]
    along = _unit(ca[2:] - ca[:-2])
    outward = before - after
    outward = _unit(outward - np.sum(outward * along, axis=1, keepdims=True) * along)
    frames = np.stack([along, outward, np.cross(along, outward)], axis=1)
    cosine = -np.sum(_unit(before) * _unit(after), axis=1)
    powers = np.stack([np.ones_like(cosine), cosine, cosine**2], axis=1)
    return np.concatenate([frames[:1], frames, frames[-1:]]), np.concatenate([powers[:1], powers, powers[-1:]])


def _unit(vectors: np.ndarray) -> np.ndarray:
    length = np.linalg.norm(vectors, axis=1, keepdims=True)
    return vectors / np.where(length > 0, length, 1.0)


@cache
def _encoder():
    import mini3di

    return mini3di.Encoder()


def states(ca: np.ndarray, atoms: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None) -> np.ndarray:
    """(n,) uint8: the 3Di state (index into :data:`STATES`) of each residue of a chain of Cα
    ``ca`` (n >= 3, 3, finite, Å). ``atoms``: its N, C and Cβ (n, 3 each; a Cβ of NaN is placed
    from N, Cα and C, as for glycine); None: N and Cβ placed by :func:`backbone_from_ca`."""
    ca = np.asarray(ca, dtype=np.float64)
    if atoms is None:
        n, cb = backbone_from_ca(ca)
        atoms = (n, n, cb)  # C only places a missing Cβ
    n, c, cb = (np.asarray(atom, dtype=np.float64) for atom in atoms)
    return np.asarray(_encoder().encode_atoms(ca, cb, n, c), dtype=np.uint8)


def amino_acid_codes(sequence: np.ndarray) -> np.ndarray:
    """(n,) uint8: the index into :data:`AMINO_ACIDS` of each one-letter code (``S1`` bytes;
    20, X, for any other)."""
    table = np.full(256, 20, dtype=np.uint8)
    table[np.frombuffer(AMINO_ACIDS[:20].encode(), dtype=np.uint8)] = np.arange(20, dtype=np.uint8)
    return table[np.asarray(sequence).view(np.uint8)]


def _matrix(text: str) -> np.ndarray:
    return np.array([[int(word) for word in line.split()] for line in text.strip().splitlines()], dtype=np.int8)


AMINO_ACID_SCORES = _matrix("""
 4 -1 -2 -2  0 -1 -1  0 -2 -1 -1 -1 -1 -2 -1  1  0 -3 -2  0  0
-1  5  0 -2 -3  1  0 -2  0 -3 -2  2 -1 -3 -2 -1 -1 -3 -2 -3 -1
-2  0  6  1 -3  0  0  0  1 -3 -3  0 -2 -3 -2  1  0 -4 -2 -3 -1
-2 -2  1  6 -3  0  2 -1 -1 -3 -4 -1 -3 -3 -1  0 -1 -4 -3 -3 -1
 0 -3 -3 -3  9 -3 -4 -3 -3 -1 -1 -3 -1 -2 -3 -1 -1 -2 -2 -1 -2
-1  1  0  0 -3  5  2 -2  0 -3 -2  1  0 -3 -1  0 -1 -2 -1 -2 -1
-1  0  0  2 -4  2  5 -2  0 -3 -3  1 -2 -3 -1  0 -1 -3 -2 -2 -1
 0 -2  0 -1 -3 -2 -2  6 -2 -4 -4 -2 -3 -3 -2  0 -2 -2 -3 -3 -1
-2  0  1 -1 -3  0  0 -2  8 -3 -3 -1 -2 -1 -2 -1 -2 -2  2 -3 -1
-1 -3 -3 -3 -1 -3 -3 -4 -3  4  2 -3  1  0 -3 -2 -1 -3 -1  3 -1
-1 -2 -3 -4 -1 -2 -3 -4 -3  2  4 -2  2  0 -3 -2 -1 -2 -1  1 -1
-1  2  0 -1 -3  1  1 -2 -1 -3 -2  5 -1 -3 -1  0 -1 -3 -2 -2 -1
-1 -1 -2 -3 -1  0 -2 -3 -2  1  2 -1  5  0 -2 -1 -1 -1 -1  1 -1
-2 -3 -3 -3 -2 -3 -3 -3 -1  0  0 -3  0  6 -4 -2 -2  1  3 -1 -1
-1 -2 -2 -1 -3 -1 -1 -2 -2 -3 -3 -1 -2 -4  7 -1 -1 -4 -3 -2 -2
 1 -1  1  0 -1  0  0  0 -1 -2 -2  0 -1 -2 -1  4  1 -3 -2 -2  0
 0 -1  0 -1 -1 -1 -1 -2 -2 -1 -1 -1 -1 -2 -1  1  5 -2 -2  0  0
-3 -3 -4 -4 -2 -2 -3 -2 -2 -3 -2 -3 -1  1 -4 -3 -2 11  2 -3 -2
-2 -2 -2 -3 -2 -1 -2 -3  2 -1 -1 -2 -1  3 -3 -2 -2  2  7 -1 -1
 0 -3 -3 -3 -1 -2 -2 -3 -3  3  1 -2  1 -1 -2 -2  0 -3 -1  4 -1
 0 -1 -1 -1 -2 -1 -1 -1 -1 -1 -1 -1 -1 -1 -2  0  0 -2 -1 -1 -1
""")
"""BLOSUM62 (half bits; Henikoff & Henikoff 1992), rows and columns in :data:`AMINO_ACIDS`' order."""

STATE_SCORES = _matrix("""
  7  -1   1   1   2  -3  -1  -6  -2  -4  -9  -5  -3   1  -4  -8  -5  -5   0  -2
 -1   7  -2  -6  -2  -5  -6 -10  -8   0  -8  -1  -1   0  -1   0  -8   0  -2 -11
  1  -2   3  -3  -1  -1   1  -4  -5  -5  -7  -4   0  -2  -2  -4  -3  -4  -3  -4
  1  -6  -3   7  -3  -6  -5  -7  -6  -7  -9 -10  -9  -4  -7 -11 -10  -9  -7   1
  2  -2  -1  -3   8  -6  -2  -4   0  -2  -6  -5  -3   2  -7  -7  -3  -5   5  -4
 -3  -5  -1  -6  -6   7   3   0  -4  -9  -2  -3  -3  -4   2  -4   4  -7  -3  -3
 -1  -6   1  -5  -2   3   7  -3  -3  -5  -9   0  -2  -5   2  -3  -3  -6  -8   2
 -6 -10  -4  -7  -4   0  -3   9  -4 -14   6  -7  -6  -8  -2  -8   6 -10  -4  -3
 -2  -8  -5  -6   0  -4  -3  -4   9 -14  -3  -7  -7  -6 -13 -11  -2 -11   5 -11
 -4   0  -5  -7  -2  -9  -5 -14 -14   8 -12  -2  -2   2  -4  -1 -14   0  -6  -8
 -9  -8  -7  -9  -6  -2  -9   6  -3 -12   9 -10  -8 -12  -3  -9   1 -14  -4  -9
 -5  -1  -4 -10  -5  -3   0  -7  -7  -2 -10   6   0  -4   3   3  -2  -1  -8 -10
 -3  -1   0  -9  -3  -3  -2  -6  -7  -2  -8   0   3  -1  -2  -1  -3   0  -6  -6
  1   0  -2  -4   2  -4  -5  -8  -6   2 -12  -4  -1   6  -2  -3  -3  -1  -3  -5
 -4  -1  -2  -7  -7   2   2  -2 -13  -4  -3   3  -2  -2   7   3   0  -2  -6  -5
 -8   0  -4 -11  -7  -4  -3  -8 -11  -1  -9   3  -1  -3   3   7  -6   0  -8  -7
 -5  -8  -3 -10  -3   4  -3   6  -2 -14   1  -2  -3  -3   0  -6  10  -8  -1  -5
 -5   0  -4  -9  -5  -7  -6 -10 -11   0 -14  -1   0  -1  -2   0  -8   3  -9 -13
  0  -2  -3  -7   5  -3  -8  -4   5  -6  -4  -8  -6  -3  -6  -8  -1  -9   9  -8
 -2 -11  -4   1  -4  -3   2  -3 -11  -8  -9 -10  -6  -5  -5  -7  -5 -13  -8   6
""")
"""3Di substitution scores (half bits), rows and columns in :data:`STATES`' order."""
