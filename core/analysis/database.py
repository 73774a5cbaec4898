"""Database analysis of wavelet levels: Cα–C^r deviations pooled over many structures.

Reproduces the quantitative results of Carson (1996), Fig. 7 (mathematics document
§10.3, §12): for every protein chain of every file, the distance ``|Cα − C^r|`` of each
residue on the low-resolution curves of both ribbons at integer and fractional
decomposition depths (:mod:`core.analysis.deviation`), then the pooled rms and standard deviation
per ribbon, mode, depth and secondary-structure class.

The choices that change the numbers are explicit in :class:`AnalysisOptions`; the
defaults describe the product (every chain, one curve per gap-free segment, N and C atoms
as terminal points, secondary structure from the file or else computed), and
:data:`REFERENCE_OPTIONS` the selection of the reference table in §12.2.

:func:`analyse_path` is the unit of parallel work: a top-level function of a path and
the options, returning plain arrays, that never raises for a bad file.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import StrEnum
from pathlib import Path

import numpy as np

from core.analysis.deviation import depth_deviations
from core.protein.reading import read_structure
from core.protein.ribbon import RibbonKind, build_ribbon
from core.protein.structure import SS_COMPUTED, BackboneSegment, Structure

RIBBONS = (RibbonKind.PEPTIDE, RibbonKind.CALPHA)
MODES = ("integer", "fractional")
CLASSES = ("all", "helix", "sheet", "other")
SS_CLASS = {"H": "helix", "E": "sheet", "C": "other"}
UNCLASSIFIED = ""
"""Class of residues that count only in 'all' (files without HELIX/SHEET records under
``SSPolicy.RECORDS``)."""


class ChainSelection(StrEnum):
    """Which protein chains of a file are analysed."""

    ALL = "all"
    LONGEST = "longest"  # the chain with most backbone residues (the first of equals)


class Gaps(StrEnum):
    """How a chain broken at a Cα–Cα gap becomes curves."""

    SPLIT = "split"  # one curve per gap-free segment (the product, math doc §8.1)
    JOIN = "join"  # one curve per chain, across its gaps (the reference of §12.2)


class Termini(StrEnum):
    """The terminal control points of a ribbon (math doc §10.1)."""

    ATOMS = "atoms"  # the N atom of the first residue and the C atom of the last, when present
    CALPHA = "calpha"  # half-bond extrapolations of the Cα (the Cα-only construction)


class SSPolicy(StrEnum):
    """Where the helix/sheet/other class of a residue comes from."""

    AUTO = "auto"  # the file's HELIX/SHEET records, else computed (DSSP)
    RECORDS = "records"  # the records only: residues of files without any count only in 'all'


@dataclass(frozen=True)
class AnalysisOptions:
    """What is analysed and how.

    Attributes
    ----------
    chains, gaps, termini, ss : see the enumerations.
    max_depth : deepest decomposition depth, integer and fractional.
    fraction_step : spacing of the fractional depths 0, step, 2 step, … max_depth.
    """

    chains: ChainSelection = ChainSelection.ALL
    gaps: Gaps = Gaps.SPLIT
    termini: Termini = Termini.ATOMS
    ss: SSPolicy = SSPolicy.AUTO
    max_depth: float = 6.0
    fraction_step: float = 0.5

    def __post_init__(self) -> None:
        for name, kind in (("chains", ChainSelection), ("gaps", Gaps), ("termini", Termini), ("ss", SSPolicy)):
            object.__setattr__(self, name, kind(getattr(self, name)))
        if not (math.isfinite(self.max_depth) and 0 <= self.max_depth <= 30):
            raise ValueError(f"max_depth must lie in [0, 30]; got {self.max_depth:g}")
        if not (math.isfinite(self.fraction_step) and self.fraction_step > 0):
            raise ValueError(f"fraction_step must be > 0; got {self.fraction_step:g}")

    @property
    def integer_depths(self) -> np.ndarray:
        """0, 1, …, ⌊max_depth⌋."""
        return np.arange(math.floor(self.max_depth + 1e-9) + 1)

    @property
    def fractional_depths(self) -> np.ndarray:
        """0, step, 2 step, … up to max_depth (rounded to 1e-9)."""
        count = math.floor(self.max_depth / self.fraction_step + 1e-9)
        return np.round(np.arange(count + 1) * self.fraction_step, 9)

    @property
    def columns(self) -> tuple[DepthColumn, ...]:
        """The deviation columns: each ribbon, integer depths then fractional depths."""
        return tuple(
            DepthColumn(ribbon, mode, float(depth))
            for ribbon in RIBBONS
            for mode, depths in zip(MODES, (self.integer_depths, self.fractional_depths))
            for depth in depths
        )


REFERENCE_OPTIONS = AnalysisOptions(
    chains=ChainSelection.LONGEST, gaps=Gaps.JOIN, termini=Termini.CALPHA, ss=SSPolicy.RECORDS
)
"""The data selection and decisions of the reference table, math doc §12.2."""


@dataclass(frozen=True)
class DepthColumn:
    """One column of deviations: a ribbon, a mode ('integer' or 'fractional') and a depth."""

    ribbon: RibbonKind
    mode: str
    depth: float

    @property
    def name(self) -> str:
        """Column name such as ``peptide_integer_2`` or ``calpha_fractional_2.5``."""
        return f"{self.ribbon.value}_{self.mode}_{self.depth:g}"


@dataclass(frozen=True, eq=False)
class FileAnalysis:
    """Per-residue deviations of one file; every array has one row per residue.

    Attributes
    ----------
    path : Path
    entry : str
    ss_source : str
        Where the file's secondary structure came from (``core.protein.structure.SS_*``).
    n_curves : int
    chain : (n,) str
    curve : (n,) int64
        Curve of the residue within its chain (0, 1, … at gaps when split; 0 when joined).
    resseq : (n,) int64
    icode, resname, ss : (n,) str
        ``ss`` is the structure's 'H', 'E' or 'C'.
    ss_class : (n,) str
        'helix', 'sheet', 'other', or :data:`UNCLASSIFIED` (counted only in 'all').
    deviations : (n, len(options.columns)) float64, Å
        ``|Cα − C^r|``; NaN beyond the lowest level of a curve.
    """

    path: Path
    entry: str
    ss_source: str
    n_curves: int
    chain: np.ndarray
    curve: np.ndarray
    resseq: np.ndarray
    icode: np.ndarray
    resname: np.ndarray
    ss: np.ndarray
    ss_class: np.ndarray
    deviations: np.ndarray

    def __len__(self) -> int:
        return len(self.resseq)


@dataclass(frozen=True)
class SkippedFile:
    """A file that could not be analysed, and why."""

    path: Path
    reason: str


@dataclass(frozen=True)
class SummaryRow:
    """Pooled statistics of one column and class: rms and SD of ``|Cα − C^r|`` in Å."""

    ribbon: str
    mode: str
    depth: float
    ss_class: str
    n_residues: int
    rms: float
    sd: float


def analyse_structure(structure: Structure, options: AnalysisOptions = AnalysisOptions()) -> FileAnalysis:
    """Deviations of every residue of the selected chains of ``structure``."""
    groups = _curves(structure, options)
    integer, fractional = options.integer_depths, options.fractional_depths
    blocks, curve_number = [], []
    for number, segments in groups:
        ca = np.concatenate([s.ca for s in segments])
        ends = {}
        if options.termini is Termini.ATOMS:
            ends = {"n_start": segments[0].n[0], "c_end": segments[-1].c[-1]}
        columns = []
        for kind in RIBBONS:
            columns += depth_deviations(build_ribbon(kind, ca, **ends), ca, integer, fractional)
        blocks.append(np.hstack(columns))
        curve_number.append(np.full(len(ca), number, dtype=np.int64))
    segments = [s for _, group in groups for s in group]
    ss = np.concatenate([s.ss for s in segments])
    classified = options.ss is SSPolicy.AUTO or structure.ss_source != SS_COMPUTED
    ss_class = np.array([SS_CLASS[c] if classified else UNCLASSIFIED for c in ss.tolist()], dtype=str)
    return FileAnalysis(
        path=structure.path,
        entry=structure.entry_id,
        ss_source=structure.ss_source,
        n_curves=len(groups),
        chain=np.repeat(np.array([s.chain for s in segments], dtype=str), [len(s) for s in segments]),
        curve=np.concatenate(curve_number),
        resseq=np.concatenate([s.resseq for s in segments]),
        icode=np.concatenate([s.icode for s in segments]),
        resname=np.concatenate([s.resname for s in segments]),
        ss=ss,
        ss_class=ss_class,
        deviations=np.vstack(blocks),
    )


def analyse_path(path: Path, options: AnalysisOptions = AnalysisOptions()) -> FileAnalysis | SkippedFile:
    """Read and analyse one file; a file that cannot be used gives a :class:`SkippedFile`.

    Never raises for a bad file (the reason names the error), so one file never stops
    a database run.
    """
    try:
        return analyse_structure(read_structure(path), options)
    except Exception as error:  # noqa: BLE001 - reported per file, the run goes on
        reason = str(error)
        prefix = f"{path}: "
        reason = reason.removeprefix(prefix) if reason.startswith(prefix) else f"{type(error).__name__}: {reason}"
        return SkippedFile(Path(path), reason)


class PooledStatistics:
    """Running sums of ``|Cα − C^r|`` per column and class, so a database of any size is
    summarised file by file in constant memory.

    Attributes
    ----------
    options : AnalysisOptions
    n_files, n_curves, n_residues : what has been added.
    n_files_without_records, n_residues_without_records : of those, the files without
        HELIX/SHEET records, whose classes were computed (``SSPolicy.AUTO``) or left out
        (``SSPolicy.RECORDS``).
    count, total, total_squares : (len(options.columns), len(CLASSES)) residues with a
        value, sum of the distances (Å) and of their squares (Å²).
    """

    def __init__(self, options: AnalysisOptions = AnalysisOptions()):
        self.options = options
        self.n_files = self.n_curves = self.n_residues = 0
        self.n_files_without_records = self.n_residues_without_records = 0
        shape = (len(options.columns), len(CLASSES))
        self.count = np.zeros(shape, dtype=np.int64)
        self.total = np.zeros(shape)
        self.total_squares = np.zeros(shape)

    def add(self, analysis: FileAnalysis) -> None:
        """Pool the residues of one file (analysed with the same options)."""
        if analysis.deviations.shape[1] != len(self.options.columns):
            raise ValueError(f"{analysis.path}: analysed with other depths ({analysis.deviations.shape[1]} columns, "
                             f"expected {len(self.options.columns)})")
        self.n_files += 1
        self.n_curves += analysis.n_curves
        self.n_residues += len(analysis)
        if analysis.ss_source == SS_COMPUTED:
            self.n_files_without_records += 1
            self.n_residues_without_records += len(analysis)
        finite = np.isfinite(analysis.deviations)
        values = np.where(finite, analysis.deviations, 0.0)
        for k, name in enumerate(CLASSES):
            rows = slice(None) if name == "all" else analysis.ss_class == name
            self.count[:, k] += finite[rows].sum(axis=0)
            self.total[:, k] += values[rows].sum(axis=0)
            self.total_squares[:, k] += (values[rows] ** 2).sum(axis=0)

    def rows(self) -> list[SummaryRow]:
        """rms and SD (population SD of the distances) per column and class with residues."""
        rows = []
        for k, column in enumerate(self.options.columns):
            for c, name in enumerate(CLASSES):
                n = int(self.count[k, c])
                if n:
                    mean, mean_square = self.total[k, c] / n, self.total_squares[k, c] / n
                    sd = math.sqrt(max(mean_square - mean**2, 0.0))
                    rows.append(SummaryRow(column.ribbon.value, column.mode, column.depth, name, n,
                                           math.sqrt(mean_square), sd))
        return rows


def summarize(analyses: list[FileAnalysis], options: AnalysisOptions = AnalysisOptions()) -> list[SummaryRow]:
    """Pooled rms and SD of ``|Cα − C^r|`` per column and class over the residues of
    ``analyses`` (see :class:`PooledStatistics`)."""
    pooled = PooledStatistics(options)
    for analysis in analyses:
        pooled.add(analysis)
    return pooled.rows()


def rms_crossing(
    rows: list[SummaryRow], threshold: float, ribbon: str = "peptide", mode: str = "fractional", ss_class: str = "all"
) -> float | None:
    """Depth at which the pooled rms first reaches ``threshold`` Å (linear between depths).

    Returns None when it stays below ``threshold`` at every depth.
    """
    series = sorted((r.depth, r.rms) for r in rows if (r.ribbon, r.mode, r.ss_class) == (ribbon, mode, ss_class))
    for (d0, r0), (d1, r1) in zip(series, series[1:]):
        if r0 < threshold <= r1:
            return d0 + (threshold - r0) * (d1 - d0) / (r1 - r0)
    return series[0][0] if series and series[0][1] >= threshold else None


def _curves(structure: Structure, options: AnalysisOptions) -> list[tuple[int, list[BackboneSegment]]]:
    """The curves to analyse: (number within the chain, the segments that make it)."""
    chains: dict[str, list[BackboneSegment]] = {}
    for segment in structure.segments:
        chains.setdefault(segment.chain, []).append(segment)
    if options.chains is ChainSelection.LONGEST:
        longest = max(chains, key=lambda name: sum(len(s) for s in chains[name]))
        chains = {longest: chains[longest]}
    if options.gaps is Gaps.JOIN:
        return [(0, segments) for segments in chains.values()]
    return [(number, [s]) for segments in chains.values() for number, s in enumerate(segments)]
