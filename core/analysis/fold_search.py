"""Fold search: every protein chain of a database as a small descriptor of its low-level
wavelet curves, ranked against a query's, and the best candidates aligned by structure.

The descriptor (:func:`curve_descriptor`) follows Carson's observation that a coarse level
keeps the overall fold with a fraction of the geometry. A chain's Cα trace, taken as the
control polygon of a cubic B-spline and resampled evenly along the chain to
``2**RESAMPLED_LEVEL + 3`` points (so that chains of every length have the same levels), is
smoothed by the curve wavelets (:func:`core.curves.wavelets.smooth`) to the least-squares
best curves of levels 2, 3 and 4 (4, 8 and 16 segments; 7, 11 and 19 control points). The
distances between the control points of each level, 21 + 55 + 171 = 247 numbers, describe
that curve whatever its position and orientation: two chains of one fold have nearly the
same profile, and the difference of two profiles (:func:`descriptor_distances`, each level
weighted alike) ranks the database in one vectorised pass. Stored as float16 (0.1 Å at
100 Å), a chain takes 494 bytes: the 230,000 entries of the PDB (about 600,000 chains)
need about 0.3 GB.

A global descriptor of the whole chain knows nothing of domains: a fold found as one domain
of a larger chain, or a chain whose termini differ in length, ranks lower than it would by
TM-score, and mirror images have equal profiles (the alignment tells them apart). The
ranking only chooses which chains to align: :func:`search` screens the nearest
``candidates`` by a quick alignment of every 4th Cα (:func:`core.analysis.tm_align.screen`),
aligns the best of them with :func:`core.analysis.fold_alignment.align_folds` and orders the
hits by TM-score, so the figures it prints are TM-align's, not the descriptor's.

:func:`index_path` is the unit of parallel work (a top-level function of a path that never
raises for a bad file); :class:`FoldIndex` holds the chains of many files, their
descriptors, Cα and sequences, and is saved as an uncompressed ``.npz`` archive of plain
arrays (read back without pickle; the Cα and sequences, 13 bytes a residue, mapped from the
file, so a search reads only its candidates' rows).
"""

from __future__ import annotations

import io
import zipfile
import zlib
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np
from scipy.spatial.distance import pdist

from core.analysis.compare import FoldMatch, fold_match
from core.analysis.database import SkippedFile
from core.analysis.fold_alignment import align_folds
from core.analysis.tm_align import screen
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
"""Index rows ranked at once."""
MIN_RESIDUES = 20
"""Chains with fewer residues are not indexed (peptides have no fold to search)."""
FORMAT = 3
"""Version of the index file (2: uncompressed, the coordinates and sequences mapped; 3: a
checksum of each chain's coordinates and sequence)."""
SCREEN_STEP = 4
"""The candidates of :func:`search` are screened by aligning every 4th Cα of each chain."""
FIELDS = ("format", "entries", "chains", "paths", "lengths", "descriptors", "checksums", "coordinates", "sequences")
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
    """(n,) the difference of each row of ``descriptors`` (n, DESCRIPTOR_SIZE) from ``query``:
    the root of the mean, over :data:`LEVELS`, of each level's mean squared distance difference, Å.
    Computed :data:`RANK_BLOCK` rows at a time, so a float16 index of the whole PDB is ranked
    without a float32 copy of it."""
    query = np.asarray(query, dtype=np.float32)
    distance = np.empty(len(descriptors))
    for first in range(0, len(descriptors), RANK_BLOCK):
        difference = np.asarray(descriptors[first:first + RANK_BLOCK], dtype=np.float32) - query
        np.square(difference, out=difference)
        distance[first:first + RANK_BLOCK] = difference @ LEVEL_WEIGHTS
    return np.sqrt(distance)


@dataclass(frozen=True, eq=False)
class FoldIndex:
    """Protein chains of many files: one row each.

    Attributes
    ----------
    entries, chains, paths : (n,) str: the entry id, chain id and file of each chain.
    lengths : (n,) int64 residues.
    descriptors : (n, DESCRIPTOR_SIZE) float16 (:func:`curve_descriptor`).
    checksums : (n,) uint32 CRC-32 of each chain's coordinates and sequence (:func:`checksum`).
    coordinates : (lengths.sum(), 3) float32 Cα of every chain, one after another, Å.
    sequences : (lengths.sum(),) one-letter residue codes (bytes), in the same order.
    """

    entries: np.ndarray
    chains: np.ndarray
    paths: np.ndarray
    lengths: np.ndarray
    descriptors: np.ndarray
    checksums: np.ndarray
    coordinates: np.ndarray
    sequences: np.ndarray

    def __len__(self) -> int:
        return len(self.entries)

    @cached_property
    def starts(self) -> np.ndarray:
        """(n,) int64: the first row of each chain in ``coordinates`` and ``sequences``."""
        return np.concatenate([[0], np.cumsum(self.lengths)[:-1]]).astype(np.int64)

    def chain(self, k: int) -> tuple[np.ndarray, np.ndarray]:
        """The Cα (float64) and one-letter codes of chain ``k``; ValueError where the file's
        coordinates of it are not finite numbers (a damaged index: they are read only now)."""
        rows = slice(int(self.starts[k]), int(self.starts[k] + self.lengths[k]))
        stored, sequence = np.asarray(self.coordinates[rows]), np.asarray(self.sequences[rows])
        ca = stored.astype(np.float64)
        if not np.isfinite(ca).all():
            raise ValueError(f"a damaged fold index: chain {k} ({self.entries[k]}:{self.chains[k]}) has non-finite "
                             f"coordinates; {REBUILD}")
        if checksum(stored, sequence) != self.checksums[k]:
            raise ValueError(f"a damaged fold index: the coordinates or sequence of chain {k} ({self.entries[k]}:"
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
        """Read an index written by :meth:`to_bytes`, its coordinates and sequences mapped from
        the file (read as the chains are used); ValueError when it is not one."""
        try:
            with np.load(path, allow_pickle=False) as archive:
                if int(archive["format"]) != FORMAT:
                    raise ValueError(f"{path}: a fold index of another format version (index the files again)")
                arrays = {name: archive[name] for name in FIELDS[1:7]}
            arrays |= {name: _mapped(path, name) for name in FIELDS[7:]}
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
        if (index.descriptors.shape != (n, DESCRIPTOR_SIZE) or len(index.lengths) != n or len(index.chains) != n
                or index.checksums.shape != (n,) or len(index.coordinates) != residues or len(index.sequences) != residues):
            raise ValueError(f"{path}: a damaged fold index (its arrays disagree); {REBUILD}")
        if (index.lengths < MIN_RESIDUES).any() or not np.isfinite(index.descriptors).all():
            raise ValueError(f"{path}: a damaged fold index (chains shorter than {MIN_RESIDUES} residues or "
                             f"descriptors that are not finite numbers); {REBUILD}")
        return index


def _mapped(path: Path, name: str) -> np.ndarray:
    """The array ``name`` of an uncompressed ``.npz`` archive, mapped read-only from the file."""
    with zipfile.ZipFile(path) as archive:
        info = archive.getinfo(f"{name}.npy")
    if info.compress_type != zipfile.ZIP_STORED:
        raise ValueError(f"{name} is compressed")
    with open(path, "rb") as file:
        file.seek(info.header_offset)
        header = file.read(30)  # the zip entry's local header, then its name and extra field
        file.seek(info.header_offset + 30 + int.from_bytes(header[26:28], "little")
                  + int.from_bytes(header[28:30], "little"))
        version = np.lib.format.read_magic(file)
        shape, fortran, dtype = (np.lib.format.read_array_header_1_0(file) if version == (1, 0)
                                 else np.lib.format.read_array_header_2_0(file))
        offset = file.tell()
    if dtype.hasobject or fortran:
        raise ValueError(f"{name} is not a plain array")
    if not np.prod(shape):
        return np.zeros(shape, dtype=dtype)
    return np.memmap(path, dtype=dtype, mode="r", offset=offset, shape=shape)


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
    return FoldIndex(
        entries=np.array([structure.entry_id] * len(names), dtype=str).reshape(-1),
        chains=np.array(names, dtype=str).reshape(-1),
        paths=np.array([str(path)] * len(names), dtype=str).reshape(-1),
        lengths=np.array([len(ca) for ca in coordinates], dtype=np.int64),
        descriptors=np.array([curve_descriptor(ca) for ca in coordinates], dtype=np.float16).reshape(
            -1, DESCRIPTOR_SIZE),
        checksums=np.array([checksum(ca, code) for ca, code in zip(coordinates, codes)], dtype=np.uint32),
        coordinates=np.concatenate(coordinates or [np.zeros((0, 3), dtype=np.float32)]),
        sequences=np.concatenate(codes or [np.zeros(0, dtype="S1")]),
    )


def checksum(coordinates: np.ndarray, sequence: np.ndarray) -> int:
    """CRC-32 of a chain's float32 Cα and one-letter codes as the index stores them."""
    return zlib.crc32(np.ascontiguousarray(sequence).tobytes(), zlib.crc32(np.ascontiguousarray(coordinates).tobytes()))


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


@dataclass(frozen=True)
class Hit:
    """One chain found by :func:`search`: its place in the index, descriptor difference (Å)
    and the structural match of the query (chain a) with it (chain b)."""

    row: int
    entry: str
    chain: str
    path: str
    length: int
    descriptor_distance: float
    match: FoldMatch


def search(index: FoldIndex, ca: np.ndarray, sequence: str, top: int = 10, candidates: int = 60,
           aligned: int = 15) -> list[Hit]:
    """The ``top`` chains of ``index`` of highest TM-score (normalised by the query) among the
    ``candidates`` nearest to the query's descriptor, best first.

    The candidates are screened by the TM-score of the alignment of every
    :data:`SCREEN_STEP`-th Cα of each chain (:func:`core.analysis.tm_align.screen`, a small
    fraction of a full alignment's work), and the best ``aligned`` of them (at least ``top``)
    aligned in full.

    Parameters
    ----------
    ca : (n >= 3, 3) the query's Cα, Å; sequence : its one-letter codes (n).
    """
    ca = np.asarray(ca, dtype=np.float64)
    distance = descriptor_distances(index.descriptors, curve_descriptor(ca))
    nearest = np.argsort(distance, kind="stable")[:max(candidates, aligned, top)]
    chains = [index.chain(row)[0] for row in nearest.tolist()]  # read from the file now
    lengths = np.array([len(other) for other in chains], dtype=np.int64)
    screened = screen(ca, np.concatenate(chains or [np.zeros((0, 3))]), np.concatenate([[0], np.cumsum(lengths)[:-1]]),
                      lengths, SCREEN_STEP)
    chosen = nearest[np.argsort(-screened, kind="stable")[:max(aligned, top)]].tolist()
    alignments = {row: align_folds(ca, index.chain(row)[0]) for row in chosen}
    best = sorted(chosen, key=lambda row: -alignments[row].tm_score)[:top]
    names = np.frombuffer(sequence.encode("ascii", "replace"), dtype="S1")
    hits = []
    for row in best:
        other, other_names = index.chain(row)
        alignment = alignments[row]
        match = fold_match(ca, other, alignment.pairs_a, alignment.pairs_b, names, other_names)
        hits.append(Hit(row, str(index.entries[row]), str(index.chains[row]), str(index.paths[row]),
                        int(index.lengths[row]), float(distance[row]), match))
    hits.sort(key=lambda hit: -hit.match.tm_score_a)
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
