"""Fold search: every protein chain of a database as the string of its residues' 3Di states
and amino acids, scored against the query's by local alignment, the best aligned by structure.

:func:`search` works as Foldseek does (van Kempen et al. 2024), from Cα alone:

1. Each chain is read as two strings (:mod:`core.analysis.structural_alphabet`): the 3Di state
   of each residue (its backbone's geometry and that of its nearest residue in space) and its
   amino acid. The Smith–Waterman score of the query against every chain
   (:func:`alignment_scores`, :mod:`core.analysis.local_alignment`: 3Di substitution scores
   plus :data:`AMINO_ACID_WEIGHT` times BLOSUM62, affine gaps) ranks the database, about 340
   million cells a CPU second, and gives each chain an E-value (:func:`evalues`).
2. The :data:`ALIGNED` best are aligned by structure: their local alignment, refined by two
   rounds of TM-align's dynamic programming on the superposed chains (:func:`refine_pairs`),
   gives the TM-score, rms and identity of each (:class:`~core.analysis.compare.FoldMatch`).
   They come first, by their fold score, the TM-score plus :data:`SCORE_SHARE` times the
   alignment score relative to the query's with itself; the others follow by score.

On SCOP40's development half (Foldseek's benchmark, ``benchmarks/bench_fold_search.py``) this
finds as many superfamilies and folds as exhaustive TM-align, and nearly all its families, at
1/150 of its CPU: the cost of a query grows with the database only by its first step.

An index of more than :data:`SCORED` chains (the PDB has 800,000) scores by local alignment
only the :data:`SCORED` / 2 nearest the query by each of two small summaries of a chain, read
whole in one vectorised pass: Carson's coarse curves (:func:`curve_descriptor`, the distances
between the control points of its curves of levels 2, 3 and 4, 247 numbers that do not change
with position or orientation) and the profile of its pairs of consecutive 3Di states
(:func:`pair_profile`, 32 numbers). Together they keep about 80% of the family matches, 55%
of the superfamily and 33% of the fold matches of SCOP40 at that scale; neither knows domains.

:func:`index_path` is the unit of parallel work (a top-level function of a path that never
raises for a bad file); :class:`FoldIndex` holds the chains of many files: their descriptors,
pair profiles, Cα, sequences and states, saved as an uncompressed ``.npz`` archive of plain arrays (read back
without pickle; the names and the per-residue arrays, 14 bytes a residue, read as they are used).
"""

from __future__ import annotations

import io
import os
import zipfile
import zlib
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cache, cached_property
from pathlib import Path

import numpy as np
from numba import njit, prange
from scipy.spatial.distance import pdist

from core.analysis.compare import SAME_FOLD, FoldMatch, fold_match
from core.analysis.database import SkippedFile
from core.analysis.fold_alignment import refine_pairs
from core.analysis.local_alignment import local_pairs, local_scores
from core.analysis.structural_alphabet import AMINO_ACID_SCORES, STATE_SCORES, amino_acid_codes, states
from core.analysis.superpose import MIN_PAIRS
from core.curves.wavelets import smooth
from core.protein.reading import read_structure
from core.protein.structure import Structure

LEVELS = (2, 3, 4)
"""Wavelet levels of the descriptor's curves (4, 8 and 16 segments)."""
RESAMPLED_LEVEL = 6
"""Chains are resampled to the ``2**6 + 3`` control points of level 6 before smoothing."""
LEVEL_SIZES = tuple((2**level + 3) * (2**level + 2) // 2 for level in LEVELS)
"""Distances per level: 21, 55, 171."""
DESCRIPTOR_SIZE = sum(LEVEL_SIZES)
LEVEL_WEIGHTS = np.concatenate([np.full(size, 1.0 / (size * len(LEVEL_SIZES)), dtype=np.float32)
                                for size in LEVEL_SIZES])
"""Each distance's weight in :func:`descriptor_distances`: each level counts alike."""
RANK_BLOCK = 8192
"""Index rows compared with the query's profile at once."""
MIN_RESIDUES = 20
"""Chains with fewer residues are not indexed (peptides have no fold to search)."""
FORMAT = 5
"""Version of the index file (2: uncompressed, the coordinates and sequences mapped; 3: a
checksum of each chain's coordinates and sequence; 4: 3Di states; 5: profiles of state pairs)."""
FIELDS = ("format", "entries", "chains", "paths", "lengths", "descriptors", "profiles", "checksums", "coordinates",
          "sequences", "states")
AMINO_ACID_WEIGHT = 0.6
"""Weight of the amino acids' BLOSUM62 score beside the 3Di states' in the local alignment."""
GAP_OPEN, GAP_EXTEND = 10.0, 1.0
"""Cost of a gap's first residue and of each further one in the local alignment, half bits."""
SCORE_SLOPE, SCORE_LOCATION, SCORE_SCALE = 15.2322, -113.9755, 18.8031
"""The local alignment scores of unrelated chains of m and n residues: ``SCORE_SLOPE ln(m n)``
plus a Gumbel variable of this location and scale (``scripts/train_fold_scores.py``)."""
SCORED = 10_000
"""Chains scored by local alignment: an index of more has its :data:`SCORED` / 2 nearest by
descriptor and :data:`SCORED` / 2 nearest by pair profile scored."""
PAIR_BASIS = Path(__file__).with_name("state_pairs.npz")
"""The weights, mean and principal axes of :func:`pair_profile` (``scripts/train_fold_scores.py``)."""
PROFILE_SIZE = 32
"""Numbers in a pair profile."""
ALIGNED = 30
"""Chains of best local alignment score that :func:`search` aligns by structure."""
REFINE_ROUNDS = 2
"""Rounds of TM-align's refinement of their local alignment (:func:`refine_pairs`)."""
MATCH_STEP = 4
"""The TM-score searches of the hits' matches start from fragments at every 4th pair."""
SCORE_SHARE = 0.7
"""Weight of the alignment score (relative to the query's with itself) beside the TM-score in
the fold score that orders the chains aligned by structure."""
TOP, MAX_EVALUE = 100, 10.0
"""Hits :func:`search` lists at most, and the E-value above which it leaves a hit out."""
LOADED = ("lengths", "descriptors", "profiles", "checksums")
"""The arrays of an index file read into memory; the others (names, paths and the per-residue
arrays) are read from the file as they are used (:class:`FileArray`)."""
REBUILD = "index the files again (ribbonwave index FILE... -o DB --overwrite)"
"""What a damaged or empty index asks for."""


def curve_descriptor(ca: np.ndarray) -> np.ndarray:
    """(DESCRIPTOR_SIZE,) float32: the distances (Å) between the control points of the chain's
    curves at :data:`LEVELS` (see the module's description); ``ca`` (n >= 2, 3), Å."""
    ca = np.asarray(ca, dtype=np.float64)
    samples = np.linspace(0.0, len(ca) - 1.0, 2**RESAMPLED_LEVEL + 3)
    points = np.stack([np.interp(samples, np.arange(len(ca)), ca[:, axis]) for axis in range(3)], axis=1)
    parts = []
    for level in sorted(LEVELS, reverse=True):  # each level from the next finer one
        points = smooth(points, level)
        parts.append(pdist(points))
    return np.concatenate(parts[::-1]).astype(np.float32)


def descriptor_distances(descriptors: np.ndarray, query: np.ndarray) -> np.ndarray:
    """(n,) the difference of each row of ``descriptors`` (n, DESCRIPTOR_SIZE; float16 as the
    index keeps them, or float32) from ``query``: the root of the mean, over :data:`LEVELS`, of
    each level's mean squared distance difference, Å. float16 rows are read as they are, never
    copied (0.8 GB as float32 for the PDB)."""
    query = np.asarray(query, dtype=np.float32)
    descriptors = np.asarray(descriptors)
    if descriptors.dtype == np.float16:
        return np.sqrt(_weighted_squares(descriptors.view(np.uint16), _HALF, query, LEVEL_WEIGHTS))
    difference = np.asarray(descriptors, dtype=np.float32) - query
    return np.sqrt(np.square(difference) @ LEVEL_WEIGHTS)


_HALF = np.arange(2**16, dtype=np.uint16).view(np.float16).astype(np.float32)
"""Every float16 by its bits, as float32."""


@njit(cache=True, parallel=True)
def _weighted_squares(bits: np.ndarray, half: np.ndarray, query: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """(n,) the weighted sum of squared differences of each row of float16 values (given by
    their ``bits``, read through the table ``half``) from ``query``."""
    out = np.empty(bits.shape[0])
    for k in prange(bits.shape[0]):
        total = 0.0
        for j in range(bits.shape[1]):
            difference = half[bits[k, j]] - query[j]
            total += weights[j] * difference * difference
        out[k] = total
    return out


@cache
def _pair_basis() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    with np.load(PAIR_BASIS) as basis:
        return basis["weights"], basis["mean"], basis["axes"]


def pair_profile(chain_states: np.ndarray) -> np.ndarray:
    """(PROFILE_SIZE,) float32 unit vector: which pairs of 3Di states follow each other along a
    chain (``chain_states``, n >= 2). The square roots of the 400 pairs' counts, weighted by how
    rare each pair is among chains (its inverse document frequency), less their mean over
    chains, on their principal axes; all learnt from the shared set."""
    chain_states = np.asarray(chain_states, dtype=np.int64)
    counts = np.bincount(chain_states[:-1] * 20 + chain_states[1:], minlength=400).astype(np.float32)
    weights, mean, axes = _pair_basis()
    profile = (np.sqrt(counts) * weights - mean) @ axes
    return (profile / max(float(np.linalg.norm(profile)), 1e-12)).astype(np.float32)


def profile_similarities(profiles: np.ndarray, query: np.ndarray) -> np.ndarray:
    """(n,) the cosine of each row of ``profiles`` (n, PROFILE_SIZE) with ``query``, computed
    :data:`RANK_BLOCK` rows at a time."""
    query = np.asarray(query, dtype=np.float32)
    similarity = np.empty(len(profiles))
    for first in range(0, len(profiles), RANK_BLOCK):
        similarity[first:first + RANK_BLOCK] = np.asarray(profiles[first:first + RANK_BLOCK], dtype=np.float32) @ query
    return similarity


@dataclass(frozen=True, eq=False)
class FoldIndex:
    """Protein chains of many files: one row each.

    Attributes
    ----------
    entries, chains, paths : (n,) str: the entry id, chain id and file of each chain.
    lengths : (n,) int64 residues.
    descriptors : (n, DESCRIPTOR_SIZE) float16 (:func:`curve_descriptor`).
    profiles : (n, PROFILE_SIZE) float16 (:func:`pair_profile`).
    checksums : (n,) uint32 CRC-32 of each chain's coordinates, sequence and states (:func:`checksum`).
    coordinates : (lengths.sum(), 3) float32 Cα of every chain, one after another, Å.
    sequences : (lengths.sum(),) one-letter residue codes (bytes), in the same order.
    states : (lengths.sum(),) uint8 3Di states (:func:`core.analysis.structural_alphabet.states`), in the same order.
    """

    entries: np.ndarray
    chains: np.ndarray
    paths: np.ndarray
    lengths: np.ndarray
    descriptors: np.ndarray
    profiles: np.ndarray
    checksums: np.ndarray
    coordinates: np.ndarray
    sequences: np.ndarray
    states: np.ndarray

    def __len__(self) -> int:
        return len(self.entries)

    @cached_property
    def starts(self) -> np.ndarray:
        """(n,) int64: the first row of each chain in ``coordinates`` and ``sequences``."""
        return np.concatenate([[0], np.cumsum(self.lengths)[:-1]]).astype(np.int64)

    def chain(self, k: int) -> tuple[np.ndarray, np.ndarray]:
        """The Cα (float64) and one-letter codes of chain ``k``; ValueError where the file's
        coordinates of it are not finite numbers or its checksum does not hold (a damaged index:
        the chain is read only now)."""
        rows = slice(int(self.starts[k]), int(self.starts[k] + self.lengths[k]))
        stored, sequence = np.asarray(self.coordinates[rows]), np.asarray(self.sequences[rows])
        ca = stored.astype(np.float64)
        if not np.isfinite(ca).all():
            raise ValueError(f"a damaged fold index: chain {k} ({self.entries[k]}:{self.chains[k]}) has non-finite "
                             f"coordinates; {REBUILD}")
        if checksum(stored, sequence, np.asarray(self.states[rows])) != self.checksums[k]:
            raise ValueError(f"a damaged fold index: the coordinates, sequence or states of chain {k} ({self.entries[k]}:"
                             f"{self.chains[k]}) changed since it was indexed; {REBUILD}")
        return ca, sequence

    def to_bytes(self) -> bytes:
        """The index as an uncompressed ``.npz`` archive of plain arrays (no pickled objects), so
        that :meth:`read` maps the coordinates and sequences instead of reading them."""
        out = io.BytesIO()
        np.savez(out, format=np.array(FORMAT), **{name: getattr(self, name) for name in FIELDS[1:]})
        return out.getvalue()

    @classmethod
    def read(cls, path: Path) -> FoldIndex:
        """Read an index written by :meth:`to_bytes`, all but :data:`LOADED` read from the file
        as they are used (:class:`FileArray`); ValueError when it is not one."""
        try:
            with np.load(path, allow_pickle=False) as archive:
                if int(archive["format"]) != FORMAT:
                    raise ValueError(f"{path}: a fold index of another format version (index the files again)")
                arrays = {name: archive[name] for name in LOADED}
            arrays |= {name: FileArray(path, name) for name in FIELDS[1:] if name not in LOADED}
        except (OSError, KeyError, EOFError, zipfile.BadZipFile) as error:
            raise ValueError(f"{path}: not a ribbonwave fold index ({type(error).__name__}: {error})") from None
        except ValueError as error:
            if "format version" in str(error):
                raise
            raise ValueError(f"{path}: not a ribbonwave fold index ({type(error).__name__}: {error})") from None
        index = cls(**arrays)
        n = len(index.entries)
        if not n:
            raise ValueError(f"{path}: a fold index of no chain; {REBUILD}")
        residues = int(index.lengths.sum())
        if (index.descriptors.shape != (n, DESCRIPTOR_SIZE) or index.profiles.shape != (n, PROFILE_SIZE)
                or len(index.lengths) != n or len(index.chains) != n
                or index.checksums.shape != (n,) or len(index.coordinates) != residues or len(index.sequences) != residues
                or index.states.shape != (residues,)):
            raise ValueError(f"{path}: a damaged fold index (its arrays disagree); {REBUILD}")
        if ((index.lengths < MIN_RESIDUES).any() or not np.isfinite(index.descriptors).all()
                or not np.isfinite(index.profiles).all()):
            raise ValueError(f"{path}: a damaged fold index (chains shorter than {MIN_RESIDUES} residues or "
                             f"descriptors or profiles that are not finite numbers); {REBUILD}")
        return index


class FileArray:
    """A plain array of an uncompressed ``.npz`` archive, read from the file as rows are asked
    for (``array[k]``, ``array[a:b]``; anything else reads it whole). Unlike a mapping, what a
    search reads stays in the system's file cache, out of the process's resident memory."""

    def __init__(self, path: Path, name: str) -> None:
        with zipfile.ZipFile(path) as archive:
            info = archive.getinfo(f"{name}.npy")
        if info.compress_type != zipfile.ZIP_STORED:
            raise ValueError(f"{name} is compressed")
        self._file = open(path, "rb")  # noqa: SIM115 - kept open for the reads, closed with the array
        self._file.seek(info.header_offset)
        header = self._file.read(30)  # the zip entry's local header, then its name and extra field
        self._file.seek(info.header_offset + 30 + int.from_bytes(header[26:28], "little")
                        + int.from_bytes(header[28:30], "little"))
        version = np.lib.format.read_magic(self._file)
        self.shape, fortran, self.dtype = (np.lib.format.read_array_header_1_0(self._file) if version == (1, 0)
                                           else np.lib.format.read_array_header_2_0(self._file))
        if self.dtype.hasobject or fortran or not self.shape:
            raise ValueError(f"{name} is not a plain array")
        self._offset = self._file.tell()
        self._row = self.dtype.itemsize * int(np.prod(self.shape[1:]))
        if self._offset + self.nbytes > os.fstat(self._file.fileno()).st_size:
            raise ValueError(f"{name} is cut short")

    def __del__(self) -> None:
        if hasattr(self, "_file"):
            self._file.close()

    @property
    def nbytes(self) -> int:
        return self._row * self.shape[0]

    def __len__(self) -> int:
        return self.shape[0]

    def __getitem__(self, key: object) -> np.ndarray:
        if isinstance(key, (int, np.integer)) and -len(self) <= key < len(self):
            return self[int(key) % len(self):int(key) % len(self) + 1][0]
        if isinstance(key, slice) and key.step in (None, 1):
            first, stop, _ = key.indices(len(self))
            count = max(stop - first, 0)
            rows = np.empty((count, *self.shape[1:]), dtype=self.dtype)
            if count and os.preadv(self._file.fileno(), [rows.view(np.uint8).reshape(-1)],
                                   self._offset + first * self._row) != rows.nbytes:
                raise ValueError("the file was cut short while it was read")
            return rows
        return np.asarray(self)[key]

    def __array__(self, dtype: np.dtype | None = None, copy: bool | None = None) -> np.ndarray:
        whole = self[:]
        return whole if dtype is None else whole.astype(dtype)


def index_structure(structure: Structure, path: Path | str = "") -> FoldIndex:
    """The index of every protein chain of ``structure`` with :data:`MIN_RESIDUES` or more
    residues (the chain's segments joined across their gaps)."""
    chains: dict[str, list] = {}
    for segment in structure.segments:
        chains.setdefault(segment.chain, []).append(segment)
    names, coordinates, sequences = [], [], []
    for name, segments in chains.items():
        ca = np.concatenate([s.ca for s in segments])
        if len(ca) >= MIN_RESIDUES:
            names.append(name)
            coordinates.append(ca)
            sequences.append("".join(s.sequence for s in segments))
    coordinates = [ca.astype(np.float32) for ca in coordinates]
    codes = [np.frombuffer(text.encode("ascii", "replace"), dtype="S1") for text in sequences]
    chain_states = [states(ca) for ca in coordinates]
    return FoldIndex(
        entries=np.array([structure.entry_id] * len(names), dtype=str).reshape(-1),
        chains=np.array(names, dtype=str).reshape(-1),
        paths=np.array([str(path)] * len(names), dtype=str).reshape(-1),
        lengths=np.array([len(ca) for ca in coordinates], dtype=np.int64),
        descriptors=np.array([curve_descriptor(ca) for ca in coordinates], dtype=np.float16).reshape(
            -1, DESCRIPTOR_SIZE),
        profiles=np.array([pair_profile(chain) for chain in chain_states], dtype=np.float16).reshape(-1, PROFILE_SIZE),
        checksums=np.array([checksum(*chain) for chain in zip(coordinates, codes, chain_states)], dtype=np.uint32),
        coordinates=np.concatenate(coordinates or [np.zeros((0, 3), dtype=np.float32)]),
        sequences=np.concatenate(codes or [np.zeros(0, dtype="S1")]),
        states=np.concatenate(chain_states or [np.zeros(0, dtype=np.uint8)]),
    )


def checksum(coordinates: np.ndarray, sequence: np.ndarray, chain_states: np.ndarray) -> int:
    """CRC-32 of a chain's float32 Cα, one-letter codes and 3Di states as the index stores them."""
    value = 0
    for array in (coordinates, sequence, chain_states):
        value = zlib.crc32(np.ascontiguousarray(array).tobytes(), value)
    return value


def index_path(path: Path) -> FoldIndex | SkippedFile:
    """Read and index one file; a file that cannot be used gives a :class:`SkippedFile`
    (never raises for a bad file)."""
    try:
        return index_structure(read_structure(path), path)
    except Exception as error:  # noqa: BLE001 - reported per file, the run goes on
        reason, prefix = str(error), f"{path}: "
        reason = reason.removeprefix(prefix) if reason.startswith(prefix) else f"{type(error).__name__}: {reason}"
        return SkippedFile(Path(path), reason)


def merge(indexes: Sequence[FoldIndex]) -> FoldIndex:
    """One index of the chains of all ``indexes`` (at least one), in order."""
    return FoldIndex(**{name: np.concatenate([getattr(index, name) for index in indexes]) for name in FIELDS[1:]})


def query_profile(chain_states: np.ndarray, sequence: np.ndarray, state_scores: np.ndarray = STATE_SCORES
                  ) -> np.ndarray:
    """(m, 20 × 21) float32: the score of each residue of a chain (its 3Di states and one-letter
    codes) against each residue code (:func:`residue_codes`): its 3Di substitution score plus
    :data:`AMINO_ACID_WEIGHT` times its BLOSUM62 score, half bits."""
    scores = (np.asarray(state_scores, dtype=np.float32)[:, None, :, None]
              + np.float32(AMINO_ACID_WEIGHT) * AMINO_ACID_SCORES.astype(np.float32)[None, :, None, :])
    return np.ascontiguousarray(scores.reshape(420, 420)[residue_codes(chain_states, sequence)])


def residue_codes(chain_states: np.ndarray, sequence: np.ndarray) -> np.ndarray:
    """(n,) int16: each residue's 3Di state and amino acid as one code, ``21 state + amino acid``."""
    return np.asarray(chain_states, dtype=np.int16) * 21 + amino_acid_codes(sequence)


def alignment_scores(index: FoldIndex, profile: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """(len(rows),) float32: the local alignment score (half bits; gaps :data:`GAP_OPEN`,
    :data:`GAP_EXTEND`) of the query's ``profile`` (:func:`query_profile`) against chains
    ``rows`` of ``index``. Reads their states and sequences (2 bytes a residue), not their Cα."""
    rows = np.asarray(rows, dtype=np.int64)
    lengths = index.lengths[rows]
    if len(rows) == len(index) and np.array_equal(rows, np.arange(len(index))):
        codes, starts = residue_codes(index.states, index.sequences), index.starts
    else:
        pieces = [slice(int(first), int(first + length)) for first, length in zip(index.starts[rows], lengths)]
        codes = residue_codes(np.concatenate([index.states[piece] for piece in pieces] or [np.zeros(0, np.uint8)]),
                              np.concatenate([index.sequences[piece] for piece in pieces] or [np.zeros(0, "S1")]))
        starts = np.concatenate([[0], np.cumsum(lengths)[:-1]]).astype(np.int64)
    return local_scores(profile, codes, starts, lengths, GAP_OPEN, GAP_EXTEND)


def evalues(scores: np.ndarray, query_length: int, lengths: np.ndarray, chains: int) -> np.ndarray:
    """The expected number of chains of unrelated folds, among ``chains``, that align to a
    query of ``query_length`` residues with a score of ``scores`` or more (chains of
    ``lengths``): a Gumbel tail whose location grows with ``ln(m n)`` (:data:`SCORE_SLOPE`,
    :data:`SCORE_LOCATION`, :data:`SCORE_SCALE`, fitted on unrelated chains)."""
    shift = (np.asarray(scores, dtype=np.float64) - SCORE_SLOPE * np.log(float(query_length) * lengths)
             - SCORE_LOCATION) / SCORE_SCALE
    return chains * -np.expm1(-np.exp(-shift))


@dataclass(frozen=True)
class Hit:
    """One chain found by :func:`search`: its place in the index, the local alignment score of
    its 3Di states and amino acids with the query's (half bits) and its E-value; for the
    chains aligned by structure, the structural match of the query (chain a) with it (chain b)
    and the fold score that orders them (None for the others)."""

    row: int
    entry: str
    chain: str
    path: str
    length: int
    score: float
    evalue: float
    match: FoldMatch | None
    fold_score: float | None


def search(index: FoldIndex, ca: np.ndarray, sequence: str, top: int = TOP, aligned: int = ALIGNED,
           max_evalue: float = MAX_EVALUE) -> list[Hit]:
    """The chains of ``index`` most like the query, best first: at most ``top``, each with an
    E-value of ``max_evalue`` or less or a TM-score of :data:`~core.analysis.compare.SAME_FOLD`
    or more.

    Every chain (of an index of more than :data:`SCORED` chains, those nearest the query by
    descriptor or by pair profile, :data:`SCORED` / 2 each) is scored by the local alignment of its 3Di states and amino acids with the
    query's; the best ``aligned`` are aligned by structure and come first, by their fold score:
    the TM-score (normalised by the query) plus :data:`SCORE_SHARE` times the alignment score
    relative to the query's with itself. The rest follow by score.

    Parameters
    ----------
    ca : (n >= 3, 3) the query's Cα, Å; sequence : its one-letter codes (n).
    """
    ca = np.asarray(ca, dtype=np.float64)
    names = np.frombuffer(sequence.encode("ascii", "replace"), dtype="S1")
    query_states = states(ca)
    profile = query_profile(query_states, names)
    if len(index) > SCORED:
        distance = descriptor_distances(index.descriptors, curve_descriptor(ca))
        similarity = profile_similarities(index.profiles, pair_profile(query_states))
        rows = np.union1d(np.argpartition(distance, SCORED // 2)[:SCORED // 2],
                          np.argpartition(-similarity, SCORED // 2)[:SCORED // 2])
    else:
        rows = np.arange(len(index))
    scores = alignment_scores(index, profile, rows)
    own = float(local_scores(profile, residue_codes(query_states, names), np.zeros(1, np.int64),
                             np.array([len(ca)]), GAP_OPEN, GAP_EXTEND)[0])
    expected = evalues(scores, len(ca), index.lengths[rows], len(index))
    order = np.argsort(-scores, kind="stable")
    matches, fold_scores = {}, {}
    for k in order[:aligned].tolist():
        row = int(rows[k])
        other, other_names = index.chain(row)
        other_states = np.asarray(index.states[index.starts[row]:index.starts[row] + index.lengths[row]])
        pairs_a, pairs_b, _ = local_pairs(profile, residue_codes(other_states, other_names), GAP_OPEN, GAP_EXTEND)
        if len(pairs_a) >= MIN_PAIRS:
            pairs_a, pairs_b = refine_pairs(ca, other, pairs_a, pairs_b, REFINE_ROUNDS)
        if len(pairs_a) >= MIN_PAIRS:
            matches[k] = fold_match(ca, other, pairs_a, pairs_b, names, other_names, MATCH_STEP)
            fold_scores[k] = matches[k].tm_score_a + SCORE_SHARE * float(scores[k]) / max(own, 1.0)
    ranked = sorted(fold_scores, key=lambda k: -fold_scores[k]) + [k for k in order.tolist() if k not in fold_scores]
    hits = []
    for k in ranked:
        match = matches.get(k)
        if expected[k] > max_evalue and (match is None or match.tm_score_a < SAME_FOLD):
            continue
        row = int(rows[k])
        hits.append(Hit(row, str(index.entries[row]), str(index.chains[row]), str(index.paths[row]),
                        int(index.lengths[row]), float(scores[k]), float(expected[k]), match, fold_scores.get(k)))
        if len(hits) == top:
            break
    return hits


def sensitivity(ranked: np.ndarray, family: np.ndarray, superfamily: np.ndarray, fold: np.ndarray,
                query: int) -> np.ndarray | None:
    """Foldseek's measure of one search: per level (same family; same superfamily, other family;
    same fold, other superfamily), the share of the query's true positives that ``ranked``
    (rows, best first; the query itself ignored) lists before the first chain of another fold.
    ``family``, ``superfamily`` and ``fold`` label every row; None when a level has no true positive."""
    kinds = np.select([family == family[query], superfamily == superfamily[query], fold == fold[query]], [0, 1, 2], 3)
    kinds[query] = -1
    totals = np.bincount(kinds[kinds >= 0], minlength=4)[:3]
    if not totals.all():
        return None
    listed = kinds[np.asarray(ranked)[np.asarray(ranked) != query]]
    false = np.flatnonzero(listed == 3)
    before = listed[:false[0]] if len(false) else listed
    return np.bincount(before[before >= 0], minlength=4)[:3] / totals
