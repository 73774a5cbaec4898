"""Three-state secondary structure (H, E, C) from backbone geometry: a compact DSSP.

Follows Kabsch & Sander (1983) and the reference DSSP program:

- amide H placed 1 Å from N along the previous residue's C=O direction (reversed);
  prolines and residues after a chain break have no H;
- electrostatic H-bond energy
  ``E = 0.084 * 332 * (1/r_ON + 1/r_CH - 1/r_OH - 1/r_CN)`` kcal/mol (floor -9.9),
  computed for residue pairs whose Cα are closer than 9 Å (scipy cKDTree); each N-H
  keeps its two best acceptors and an H-bond exists where ``E < -0.5``;
- n-turns at i-1 and i make the minimal helix i..i+n-1: α (n = 4, DSSP's H) first, then
  π (n = 5, I) and 3₁₀ (n = 3, G) where still coil;
- parallel and antiparallel bridges, ladders of consecutive bridges and β-bulges
  (gaps < 3 residues on one strand and < 6 on the other) give E (DSSP's E).

Three states: H = DSSP H, G or I; E = DSSP E; C = everything else, including isolated
bridges (B), turns and bends. Helices win over strands, as in DSSP.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree

HBOND_ENERGY_CUTOFF = -0.5
"""An H-bond exists where the electrostatic energy is below this (kcal/mol)."""

_COUPLING = 0.084 * 332.0  # kcal/mol·Å
_MIN_ENERGY = -9.9  # kcal/mol
_MIN_DISTANCE = 0.5  # Å: closer atoms give the floor energy
_MAX_CA_DISTANCE = 9.0  # Å: no H-bond between residues further apart
_CHUNK = 2048
"""Acceptor residues whose H-bond candidates are looked at together."""
_MAX_PEPTIDE_BOND = 2.5  # Å: a longer C(i-1)-N(i) distance is a chain break


def dssp(
    n: NDArray[np.float64],
    ca: NDArray[np.float64],
    c: NDArray[np.float64],
    o: NDArray[np.float64],
    *,
    chain_start: NDArray[np.bool_] | None = None,
    proline: NDArray[np.bool_] | None = None,
    helix_caps: bool = False,
) -> NDArray[np.str_]:
    """Assign H (helix), E (β-ladder) or C (other) to every residue.

    Parameters
    ----------
    n, ca, c, o : (M, 3) float arrays, Å
        Backbone atoms of M residues in sequence order; NaN where an atom is missing
        (such residues form no H-bonds). Several chains may follow one another.
    chain_start : (M,) bool, optional
        True for the first residue of each chain or segment: it is never peptide-bonded
        to the residue before it. Bonds are also broken where C(i-1)-N(i) > 2.5 Å.
    proline : (M,) bool, optional
        Residues without an amide hydrogen (prolines): never H-bond donors.
    helix_caps : bool
        Also count as helix the coil residue just before and just after each helix
        (whose C=O / N-H make its first / last H-bond), the convention of the wwPDB
        HELIX annotation, which is one residue longer at each end than DSSP's H.

    Returns
    -------
    (M,) array of str
        'H', 'E' or 'C' per residue.
    """
    n, ca, c, o = (np.asarray(a, dtype=np.float64).reshape(-1, 3) for a in (n, ca, c, o))
    m = len(ca)
    if not len(n) == len(c) == len(o) == m:
        raise ValueError(f"n, ca, c, o must have the same length; got {len(n)}, {m}, {len(c)}, {len(o)}")
    chain_start = np.zeros(m, bool) if chain_start is None else np.asarray(chain_start, bool)
    proline = np.zeros(m, bool) if proline is None else np.asarray(proline, bool)
    ss = np.full(m, "C", dtype="<U1")
    if m < 3:
        return ss
    bonded = _peptide_bonded(n, c, chain_start)
    run = np.cumsum(~bonded)  # residues i..k are one unbroken stretch iff run[i] == run[k]
    hbonds = _HBonds(*_hbond_pairs(n, ca, c, o, _amide_hydrogens(n, c, o, bonded, proline)), m)
    ss[_ladder_residues(hbonds, run)] = "E"
    ss[_minimal_helices(hbonds, run, 4)] = "H"
    for n in (5, 3):  # π and 3-10 helices fill what is still coil
        helix = _minimal_helices(hbonds, run, n)
        ss[helix & (ss == "C")] = "H"
    if helix_caps:
        ss[_caps(ss == "H", run) & (ss == "C")] = "H"
    return ss


def _peptide_bonded(n: np.ndarray, c: np.ndarray, chain_start: np.ndarray) -> np.ndarray:
    """(M,) bool: residue i is peptide-bonded to residue i-1."""
    bonded = np.zeros(len(n), bool)
    with np.errstate(invalid="ignore"):
        bonded[1:] = np.linalg.norm(n[1:] - c[:-1], axis=1) < _MAX_PEPTIDE_BOND
    return bonded & ~chain_start


def _amide_hydrogens(
    n: np.ndarray, c: np.ndarray, o: np.ndarray, bonded: np.ndarray, proline: np.ndarray
) -> np.ndarray:
    """(M, 3) amide H positions, NaN for residues without one."""
    h = np.full_like(n, np.nan)
    co = c[:-1] - o[:-1]
    with np.errstate(invalid="ignore", divide="ignore"):
        h[1:] = n[1:] + co / np.linalg.norm(co, axis=1, keepdims=True)
    h[~bonded | proline] = np.nan
    return h


def _hbond_pairs(
    n: np.ndarray, ca: np.ndarray, c: np.ndarray, o: np.ndarray, h: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """(acceptor C=O residue, donor N-H residue) index arrays of all H-bonds.

    Candidates are the residue pairs with Cα closer than 9 Å (a k-d tree), taken
    :data:`_CHUNK` acceptors at a time and reduced to those below the energy cutoff before
    the next chunk, so memory stays in proportion to the chain however dense it is packed.
    """
    finite = np.flatnonzero(np.isfinite(ca).all(axis=1))
    tree = cKDTree(ca[finite])
    found = []
    for start in range(0, len(finite), _CHUNK):
        rows = finite[start : start + _CHUNK]
        near = cKDTree(ca[rows]).sparse_distance_matrix(tree, _MAX_CA_DISTANCE, output_type="ndarray")
        acc, don = rows[near["i"]], finite[near["j"]]
        keep = (don != acc) & (don != acc + 1) & np.isfinite(h[don]).all(axis=1)
        acc, don = acc[keep], don[keep]
        energy = _hbond_energy(o[acc], c[acc], n[don], h[don])
        below = energy < HBOND_ENERGY_CUTOFF  # only these can be bonds: the rest go now
        found.append((acc[below], don[below], energy[below]))
    acc, don, energy = (np.concatenate(parts) for parts in zip(*found)) if found else (np.zeros(0, int),) * 3
    # Each N-H keeps its two lowest-energy acceptors (as in DSSP).
    order = np.lexsort((energy, don))
    acc, don = acc[order], don[order]
    first_of_donor = np.searchsorted(don, don, side="left")
    best_two = np.arange(len(don)) - first_of_donor < 2
    return acc[best_two], don[best_two]


def _hbond_energy(o: np.ndarray, c: np.ndarray, n: np.ndarray, h: np.ndarray) -> np.ndarray:
    """Kabsch-Sander energy (kcal/mol) of C=O ... H-N for rows of (K, 3) arrays; NaN kept."""
    r_on, r_ch, r_oh, r_cn = (np.linalg.norm(a - b, axis=1) for a, b in ((o, n), (c, h), (o, h), (c, n)))
    with np.errstate(divide="ignore", invalid="ignore"):
        energy = _COUPLING * (1 / r_on + 1 / r_ch - 1 / r_oh - 1 / r_cn)
    too_close = np.minimum.reduce([r_on, r_ch, r_oh, r_cn]) < _MIN_DISTANCE
    energy[too_close] = _MIN_ENERGY
    return np.maximum(energy, _MIN_ENERGY)


class _HBonds:
    """Set of H-bonds (acceptor C=O of a, donor N-H of d) with vectorised look-up."""

    def __init__(self, acc: np.ndarray, don: np.ndarray, m: int) -> None:
        self._m = m
        self._keys = np.unique(acc.astype(np.int64) * m + don)
        self.acc, self.don = np.divmod(self._keys, m)

    def __call__(self, a: np.ndarray, d: np.ndarray) -> np.ndarray:
        """Bool array: is there an H-bond from C=O of ``a`` to N-H of ``d``?"""
        a, d = np.broadcast_arrays(np.asarray(a, np.int64), np.asarray(d, np.int64))
        if len(self._keys) == 0:
            return np.zeros(a.shape, bool)
        valid = (a >= 0) & (a < self._m) & (d >= 0) & (d < self._m)
        keys = np.where(valid, a * self._m + d, -1)
        pos = np.searchsorted(self._keys, keys).clip(max=len(self._keys) - 1)
        return valid & (self._keys[pos] == keys)


def _caps(helix: np.ndarray, run: np.ndarray) -> np.ndarray:
    """(M,) bool: residues right before or after a helix in the same unbroken stretch."""
    same = run[1:] == run[:-1]
    caps = np.zeros_like(helix)
    caps[:-1] |= helix[1:] & same
    caps[1:] |= helix[:-1] & same
    return caps & ~helix


def _minimal_helices(hb: _HBonds, run: np.ndarray, n: int) -> np.ndarray:
    """(M,) bool: residues of minimal n-helices (n-turns at i-1 and i make i..i+n-1)."""
    m = len(run)
    i = np.arange(max(m - n, 0))
    turn = np.zeros(m, bool)
    turn[i] = hb(i, i + n) & (run[i] == run[i + n])
    start = np.zeros(m, bool)
    start[1:] = turn[1:] & turn[:-1]
    helix = np.zeros(m, bool)
    for k in range(min(n, m)):  # a chain shorter than the helix has none
        helix[k:] |= start[: m - k]
    return helix


def _ladder_residues(hb: _HBonds, run: np.ndarray) -> np.ndarray:
    """(M,) bool: residues in β-ladders (two or more bridges, bulges included)."""
    i, j, parallel = _bridges(hb, run)
    strand = np.zeros(len(run), bool)
    if len(i) == 0:
        return strand
    ladders = _ladders(i, j, parallel)
    for group in _merge_bulges(ladders, run):
        if sum(len(ladders[k][0]) for k in group) < 2:
            continue  # an isolated bridge (B) is not a strand
        for side in (0, 1):
            ends = np.concatenate([ladders[k][side] for k in group])
            strand[ends.min() : ends.max() + 1] = True
    return strand


def _bridges(hb: _HBonds, run: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Bridge partners (i < j, j >= i + 3) and whether each bridge is parallel."""
    m = len(run)
    a, d = hb.acc, hb.don
    # Every bridge contains an H-bond a -> d with {i, j} = {a+1, d}, {a, d} or {a+1, d-1}.
    first = np.concatenate([a + 1, a, a + 1])
    second = np.concatenate([d, d, d - 1])
    pairs = np.unique(np.stack([np.minimum(first, second), np.maximum(first, second)], axis=1), axis=0)
    i, j = pairs[:, 0], pairs[:, 1]
    ok = (j - i >= 3) & (i >= 1) & (j <= m - 2)
    i, j = i[ok], j[ok]
    unbroken = (run[i - 1] == run[i + 1]) & (run[j - 1] == run[j + 1])
    parallel = (hb(i - 1, j) & hb(j, i + 1)) | (hb(j - 1, i) & hb(i, j + 1))
    antiparallel = (hb(i, j) & hb(j, i)) | (hb(i - 1, j + 1) & hb(j - 1, i + 1))
    keep = unbroken & (parallel | antiparallel)
    return i[keep], j[keep], parallel[keep]


def _ladders(
    i: np.ndarray, j: np.ndarray, parallel: np.ndarray
) -> list[tuple[np.ndarray, np.ndarray, bool]]:
    """Group bridges into ladders: (i residues, j residues, parallel) sorted by first i."""
    order = np.lexsort((j, i))
    ladder_of: dict[tuple[int, int, bool], int] = {}
    members: list[tuple[list[int], list[int], bool]] = []
    for ii, jj, par in zip(i[order].tolist(), j[order].tolist(), parallel[order].tolist(), strict=True):
        k = ladder_of.get((ii - 1, jj - 1 if par else jj + 1, par))
        if k is None:
            k = len(members)
            members.append(([], [], par))
        ladder_of[(ii, jj, par)] = k
        members[k][0].append(ii)
        members[k][1].append(jj)
    return [(np.array(ii), np.array(jj), par) for ii, jj, par in members]


def _merge_bulges(
    ladders: list[tuple[np.ndarray, np.ndarray, bool]], run: np.ndarray
) -> list[list[int]]:
    """Groups of ladder indices joined by β-bulges (DSSP's gap rules), transitively."""
    parent = list(range(len(ladders)))

    def root(k: int) -> int:
        while parent[k] != k:
            k = parent[k]
        return k

    for p, (ip, jp, par) in enumerate(ladders):
        for q in range(p + 1, len(ladders)):
            iq, jq, par_q = ladders[q]
            if par_q != par:
                continue
            gap_i = iq.min() - ip.max()
            gap_j = jq.min() - jp.max() if par else jp.min() - jq.max()
            if not (0 <= gap_i < 6 and gap_j >= 0):
                continue
            if not ((gap_j < 6 and gap_i < 3) or gap_j < 3):
                continue
            span_i = (min(ip.min(), iq.min()), max(ip.max(), iq.max()))
            span_j = (min(jp.min(), jq.min()), max(jp.max(), jq.max()))
            if run[span_i[0]] == run[span_i[1]] and run[span_j[0]] == run[span_j[1]]:
                parent[root(q)] = root(p)
    groups: dict[int, list[int]] = {}
    for k in range(len(ladders)):
        groups.setdefault(root(k), []).append(k)
    return list(groups.values())
