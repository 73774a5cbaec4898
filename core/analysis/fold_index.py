"""The fold index: every protein chain of many files, its Cα, sequence and 3Di states, and two
small summaries that rank a large index in one pass.

:func:`index_path` is the unit of parallel work (a top-level function of a path that never
raises for a bad file); :func:`merge` joins the results. :class:`FoldIndex` is saved as an
uncompressed ``.npz`` archive of plain arrays, read back without pickle: the summaries,
lengths and checksums into memory, the names and the per-residue arrays (14 bytes a residue)
from the file as they are used (:class:`FileArray`), each chain checked against its CRC-32.

The summaries, for an index too large to align with every chain
(:func:`core.analysis.fold_search.chains_scored`):

- :func:`curve_descriptor`, Carson's coarse curves: the Cα trace resampled evenly to the
  control points of level 6, smoothed by the curve wavelets to its least-squares best curves
  of levels 2, 3 and 4 (4, 8 and 16 segments), and the distances between their 7, 11 and 19
  control points, 247 numbers that do not change with position or orientation, 494 bytes as
  float16 (:func:`descriptor_distances`);
- :func:`pair_profile`, which 3Di states follow each other along the chain, 32 numbers
  (:func:`profile_similarities`).

Both describe the whole chain: a fold that is one domain of a larger chain, or a chain with
long loose ends, is farther than its TM-score would put it.
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

from core.analysis.database import SkippedFile
from core.analysis.structural_alphabet import states
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
PAIR_BASIS = Path(__file__).with_name("state_pairs.npz")
"""The weights, mean and principal axes of :func:`pair_profile` (``scripts/train_fold_scores.py``)."""
PROFILE_SIZE = 32
"""Numbers in a pair profile."""
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
