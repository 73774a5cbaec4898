"""Learn the numbers of the fold search's alignment from a folder of structures with full
backbones (the project used the 255 entries of its shared set; never a labelled SCOP set).

Usage: ``python scripts/train_fold_scores.py FOLDER [--neighbours K]``. Prints, as Python to
paste into :mod:`core.analysis.structural_alphabet` and :mod:`core.analysis.fold_search`:

1. ``N_OFFSETS`` and ``CB_OFFSETS``: N and Cβ in the frame of each residue's Cα and its two
   neighbours, linear in the Cα angle's cosine and its square (least squares over every
   residue with N, Cα and Cβ whose neighbours are 4.2 Å or less away); the rms of the fit and
   the share of residues whose 3Di state from Cα alone is that of their full backbone.
2. ``STATE_SCORES``: 3Di log-odds in half bits, ``2 log2(p_ab / (p_a p_b))``, from the
   residue pairs within 5 Å of the structural alignments (:func:`align_folds`) of similar
   chains of different entries: each chain with its ``K`` nearest by descriptor, kept where
   the TM-score (normalised by the shorter chain) is 0.6 or more and fewer than half the
   pairs share their amino acid (so that no protein's copies dominate).
3. ``SCORE_SLOPE``, ``SCORE_LOCATION``, ``SCORE_SCALE``: the local alignment scores (with the
   search's scoring) of every other pair of chains of different entries, unrelated nearly all,
   fitted as ``slope ln(m n)`` plus a Gumbel variable (location, scale): the search's E-values.

It writes ``core/analysis/state_pairs.npz`` (first, as the index needs it): the pair profile's
weights (the inverse document frequency of each of the 400 pairs of 3Di states over the
chains), mean and its :data:`~core.analysis.fold_index.PROFILE_SIZE` principal axes.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import gemmi
import numpy as np
from scipy import stats

from app.cli.batch import structure_paths
from core.analysis.fold_alignment import align_folds
from core.analysis.fold_index import PAIR_BASIS, PROFILE_SIZE, FoldIndex, descriptor_distances, index_path, merge
from core.analysis.fold_search import alignment_scores, query_profile
from core.analysis.structural_alphabet import STATES, residue_frames, states

PEPTIDE = 4.2
"""Å: neighbouring Cα farther apart are not bonded."""


def backbones(paths: list[Path]) -> list[np.ndarray]:
    """(n, 4, 3) N, Cα, C, Cβ (NaN where missing) of every run of bonded amino acids of the first model."""
    runs = []
    for path in paths:
        structure = gemmi.read_structure(str(path))
        structure.setup_entities()
        for chain in structure[0]:
            rows = []
            for residue in chain.get_polymer():
                atoms = {atom.name: atom.pos.tolist() for atom in residue}
                if "CA" in atoms and gemmi.find_tabulated_residue(residue.name) is not None and \
                        gemmi.find_tabulated_residue(residue.name).is_amino_acid():
                    rows.append([atoms.get(name, [np.nan] * 3) for name in ("N", "CA", "C", "CB")])
            rows = np.array(rows, dtype=np.float64).reshape(-1, 4, 3)
            if len(rows) < 3:
                continue
            breaks = np.flatnonzero(np.linalg.norm(np.diff(rows[:, 1], axis=0), axis=1) > PEPTIDE) + 1
            runs += [run for run in np.split(rows, breaks) if len(run) >= 3]
    return runs


def fit_offsets(runs: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    powers, n_local, cb_local = [], [], []
    for run in runs:
        frames, power = residue_frames(run[:, 1])
        inner = slice(1, len(run) - 1)
        full = np.isfinite(run[inner]).all(axis=(1, 2))
        powers.append(power[inner][full])
        for atom, out in ((0, n_local), (3, cb_local)):
            out.append(np.einsum("nij,nj->ni", frames[inner][full], run[inner, atom][full] - run[inner, 1][full]))
    powers = np.concatenate(powers)
    fitted = []
    for name, local in (("N", np.concatenate(n_local)), ("CB", np.concatenate(cb_local))):
        offsets = np.linalg.lstsq(powers, local, rcond=None)[0]
        rms = np.sqrt(np.mean(np.sum((powers @ offsets - local) ** 2, axis=1)))
        print(f"# {name}: {len(local)} residues, rms {rms:.3f} Å")
        fitted.append(offsets)
    return fitted[0], fitted[1]


def agreement(runs: list[np.ndarray]) -> float:
    same = total = 0
    for run in runs:
        if len(run) < 20 or not np.isfinite(run[:, :3]).all():
            continue
        same += int(np.sum(states(run[:, 1], (run[:, 0], run[:, 2], run[:, 3])) == states(run[:, 1])))
        total += len(run)
    return same / total


def similar_pairs(index: FoldIndex, neighbours: int) -> tuple[list[tuple[np.ndarray, np.ndarray]], set]:
    pairs, seen = [], set()
    for k in range(len(index)):
        distance = descriptor_distances(index.descriptors, index.descriptors[k])
        distance[index.entries == index.entries[k]] = np.inf
        for other in np.argsort(distance, kind="stable")[:neighbours].tolist():
            key = (min(k, other), max(k, other))
            if key in seen:
                continue
            seen.add(key)
            a, b = sorted(key, key=lambda row: int(index.lengths[row]))
            (ca_a, names_a), (ca_b, names_b) = index.chain(a), index.chain(b)
            alignment = align_folds(ca_a, ca_b)
            pairs_a, pairs_b = alignment.within(ca_a, ca_b, 5.0)
            if alignment.tm_score >= 0.6 and np.mean(names_a[pairs_a] == names_b[pairs_b]) < 0.5:
                pairs.append((index.states[index.starts[a] + pairs_a], index.states[index.starts[b] + pairs_b]))
    return pairs, seen


def log_odds(pairs: list[tuple[np.ndarray, np.ndarray]], states: np.ndarray) -> np.ndarray:
    counts = np.ones((20, 20))
    for a, b in pairs:
        np.add.at(counts, (a, b), 1)
        np.add.at(counts, (b, a), 1)
    background = np.bincount(states, minlength=20) + 1.0
    background /= background.sum()
    return np.rint(2 * np.log2(counts / counts.sum() / np.outer(background, background))).astype(int)


def calibrate(index: FoldIndex, related: set, matrix: np.ndarray) -> tuple[float, float, float]:
    lengths, scores = [], []
    for k in range(len(index)):
        others = np.array([other for other in range(k + 1, len(index)) if index.entries[other] != index.entries[k]
                           and (k, other) not in related], dtype=np.int64)
        if not len(others):
            continue
        rows = slice(int(index.starts[k]), int(index.starts[k] + index.lengths[k]))
        scores.append(alignment_scores(index, query_profile(index.states[rows], index.sequences[rows], matrix), others))
        lengths.append(np.log(float(index.lengths[k]) * index.lengths[others]))
    lengths, scores = np.concatenate(lengths), np.concatenate(scores)
    slope = np.polyfit(lengths, scores, 1)[0]
    location, scale = stats.gumbel_r.fit(scores - slope * lengths)
    print(f"# {len(scores)} pairs of unrelated chains")
    return float(slope), float(location), float(scale)


def pair_basis(runs: list[np.ndarray]) -> None:
    counts = []
    for run in runs:
        if len(run) >= 20:
            chain = states(run[:, 1]).astype(np.int64)
            counts.append(np.bincount(chain[:-1] * 20 + chain[1:], minlength=400))
    counts = np.array(counts, dtype=np.float64)
    weights = np.log(len(counts) / (1.0 + np.count_nonzero(counts, axis=0)))
    vectors = np.sqrt(counts) * weights
    mean = vectors.mean(axis=0)
    axes = np.linalg.svd(vectors - mean, full_matrices=False)[2][:PROFILE_SIZE].T
    np.savez(PAIR_BASIS, weights=weights.astype(np.float32), mean=mean.astype(np.float32),
             axes=axes.astype(np.float32))
    print(f"# wrote {PAIR_BASIS.name}: {len(counts)} chains")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("folder", type=Path)
    parser.add_argument("--neighbours", type=int, default=10)
    args = parser.parse_args()
    paths = structure_paths([args.folder])
    runs = backbones(paths)
    n_offsets, cb_offsets = fit_offsets(runs)
    print(f"N_OFFSETS = np.array({np.round(n_offsets, 4).tolist()})")
    print(f"CB_OFFSETS = np.array({np.round(cb_offsets, 4).tolist()})")
    print(f"# 3Di from Cα alone as from the full backbone: {agreement(runs):.3f} of the residues")
    pair_basis(runs)
    index = merge([found for found in map(index_path, paths) if isinstance(found, FoldIndex) and len(found)])
    pairs, seen = similar_pairs(index, args.neighbours)
    print(f"# {len(pairs)} similar pairs of {len(seen)} aligned, {sum(len(a) for a, _ in pairs)} residue pairs")
    matrix = log_odds(pairs, np.asarray(index.states))
    print("STATE_SCORES = _matrix(\"\"\"\n" + "\n".join(" ".join(f"{v:3d}" for v in row) for row in matrix)
          + "\n\"\"\")")
    print(f"# in the order {STATES}")
    slope, location, scale = calibrate(index, seen, matrix)
    print(f"SCORE_SLOPE, SCORE_LOCATION, SCORE_SCALE = {slope:.4f}, {location:.4f}, {scale:.4f}")


if __name__ == "__main__":
    main()
