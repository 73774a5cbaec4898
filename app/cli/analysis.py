"""``ribbonwave analyze``: Carson's Fig. 7 over many files. Core does the science
(:mod:`core.analysis.database`); this module reads arguments, runs the files in parallel
(:mod:`app.cli.batch`), writes CSV and PNG and prints.

Output formats are a contract for other programs: the columns of ``summary.csv``,
``residues.csv`` and ``skipped.csv``.
"""

from __future__ import annotations

import argparse
import contextlib
import csv
import functools
import io
import os
import shutil
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path

import numpy as np
from tqdm import tqdm

from app.arguments import bounded
from app.cli.batch import batch_arguments, run_tasks, structure_paths
from app.errors import InputError, printable
from core.analysis.database import (
    CLASSES,
    MODES,
    RIBBONS,
    AnalysisOptions,
    ChainSelection,
    FileAnalysis,
    Gaps,
    PooledStatistics,
    SkippedFile,
    SSPolicy,
    SummaryRow,
    Termini,
    analyse_path,
    rms_crossing,
)
from core.protein.writing import process_alive

NAMES = "backslashreplace"
"""How a file name that is not UTF-8 is written in a CSV: its odd bytes as Python names them
(the byte 0xE9 of ``ub?.pdb`` as ``ub\\udce9.pdb``), so every output stays UTF-8."""

SUMMARY_COLUMNS = ("ribbon", "mode", "depth", "class", "n_residues", "rms", "sd")
RESIDUE_COLUMNS = ("file", "entry", "chain", "curve", "resseq", "icode", "resname", "ss", "class")
OUTPUTS = ("residues.csv", "summary.csv", "skipped.csv", "fig7.png")
STAGING_PREFIX = ".analyze-"
"""Outputs are written into a new folder ``OUTDIR/.analyze-PID-XXXXXXXX``, then moved into place."""
FORMULA_STARTS = ("=", "+", "-", "@", "\t", "\r")
CA_CA = 3.8
"""Ideal Cα–Cα distance (Å): the rms a coarse curve should stay below (Carson 1996)."""
PAPER = {2: 2.1, 3: 3.3}
"""Carson's pooled rms (Å) of the peptide-plane ribbon at integer depths 2 and 3."""
CLASS_COLOURS = {"all": "black", "helix": "tab:red", "sheet": "tab:blue", "other": "tab:gray"}
RIBBON_TITLES = {"peptide": "peptide-plane ribbon", "calpha": "Cα ribbon"}
Outcome = tuple[FileAnalysis | SkippedFile, str]
"""A file's analysis (or why it was skipped) and its ``residues.csv`` rows."""


def analyze_arguments(parser: argparse.ArgumentParser) -> None:
    batch_arguments(parser)
    parser.add_argument("-o", "--output", required=True, type=Path, metavar="OUTDIR",
                        help="folder for residues.csv, summary.csv, skipped.csv and fig7.png (created if needed)")
    parser.add_argument("--overwrite", action="store_true", help="replace those files if OUTDIR already has them")
    parser.add_argument("--chains", choices=[c.value for c in ChainSelection], default="all",
                        help="every protein chain (default) or only the longest chain of each file")
    parser.add_argument("--gaps", choices=[g.value for g in Gaps], default="split",
                        help="a chain broken at a Cα–Cα gap gives one curve per piece (split, default) or one curve (join)")
    parser.add_argument("--termini", choices=[t.value for t in Termini], default="atoms",
                        help="terminal ribbon points: the N and C atoms when present (atoms, default) "
                        "or half-bond extrapolations of the Cα (calpha)")
    parser.add_argument("--ss", choices=[s.value for s in SSPolicy], default="auto",
                        help="helix/sheet/other from the file's HELIX/SHEET records, else computed by DSSP (auto, "
                        "default); records: files without records count only in class 'all'")
    parser.add_argument("--max-depth", type=bounded(float, 0, 30), default=AnalysisOptions.max_depth, metavar="D",
                        help="deepest decomposition step (default %(default)g)")
    parser.add_argument("--fraction-step", type=bounded(float, 0.05, 30), default=AnalysisOptions.fraction_step, metavar="S",
                        help="spacing of the fractional depths (default %(default)g)")


def run_analyze(args: argparse.Namespace) -> int:
    try:
        options = AnalysisOptions(args.chains, args.gaps, args.termini, args.ss, args.max_depth, args.fraction_step)
    except ValueError as error:
        raise InputError(str(error)) from None
    paths = structure_paths(args.paths)
    _prepare_output(args.output, args.overwrite)
    pooled, skipped = PooledStatistics(options), []
    waiting: dict[int, Outcome] = {}  # finished out of order
    with (_staging(args.output) as staging, (staging / "residues.csv").open("w", encoding="utf-8", errors=NAMES) as table,
          tqdm(total=len(paths), unit="file", desc="analysing", file=sys.stderr, mininterval=0.5) as progress):
        table.write(",".join(RESIDUE_COLUMNS + tuple(c.name for c in options.columns)) + "\n")
        task = functools.partial(analyse_file, options=options)
        for index, (result, lines) in run_tasks(task, paths, args.jobs, args.scheduler, _failed_file):
            progress.update()
            if isinstance(result, SkippedFile):
                progress.write(f"skipped {_named(result.path)}: {result.reason}", file=sys.stderr)
            waiting[index] = result, lines
            while (pooled.n_files + len(skipped)) in waiting:  # keep the files in input order
                ready, lines = waiting.pop(pooled.n_files + len(skipped))
                if isinstance(ready, SkippedFile):
                    skipped.append(ready)
                else:
                    pooled.add(ready)
                    table.write(lines)
        table.close()
        rows = pooled.rows()
        (staging / "summary.csv").write_text(summary_csv(rows), encoding="utf-8")
        (staging / "skipped.csv").write_text(
            _csv_text([("file", "reason")] + [(_cell(str(s.path)), _cell(s.reason)) for s in skipped]), encoding="utf-8",
            errors=NAMES)
        plot_fig7(rows, staging / "fig7.png")
        for name in OUTPUTS:  # all four at once, at the end: a killed run leaves the old set
            os.replace(staging / name, args.output / name)
    print(summary_text(pooled, skipped, args.output))
    if not pooled.n_files:
        raise InputError(f"no file could be analysed: all {len(skipped)} were skipped "
                         f"(see {args.output / 'skipped.csv'})")
    return 0


def analyse_file(path: Path, options: AnalysisOptions) -> Outcome:
    """The task run by a worker: the rows are formatted there too, in parallel."""
    result = analyse_path(path, options)
    return result, residue_lines(result) if isinstance(result, FileAnalysis) else ""


def _failed_file(path: Path, reason: str) -> Outcome:
    return SkippedFile(path, reason), ""


def _prepare_output(folder: Path, overwrite: bool) -> None:
    """Check the output folder before any work: creatable, writable, and no outputs to replace
    unless ``overwrite``; remove what runs killed in it left behind."""
    if folder.exists() and not folder.is_dir():
        raise InputError(f"{folder}: exists and is not a folder")
    existing = [name for name in OUTPUTS if (folder / name).is_symlink() or (folder / name).exists()]
    if existing and not overwrite:
        raise InputError(f"{folder}: already has {', '.join(existing)}; use --overwrite to replace them")
    for name in existing:
        if (folder / name).is_dir() and not (folder / name).is_symlink():
            raise InputError(f"{folder / name}: is a folder; remove it or choose another output folder")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise InputError(f"{folder}: cannot create the folder ({error.strerror})") from None
    if not os.access(folder, os.W_OK | os.X_OK):
        raise InputError(f"{folder}: cannot write in the folder (permission denied)")
    for stale in folder.glob(f"{STAGING_PREFIX}*"):
        pid = stale.name.removeprefix(STAGING_PREFIX).split("-")[0]
        if stale.is_dir() and not stale.is_symlink() and pid.isdigit() and not process_alive(int(pid)):
            shutil.rmtree(stale, ignore_errors=True)


@contextlib.contextmanager
def _staging(folder: Path) -> Iterator[Path]:
    """A new private folder inside ``folder`` (an unpredictable name, mode 0700: no link
    planted in it can redirect a write) for the outputs until they move into place."""
    try:
        staging = Path(tempfile.mkdtemp(prefix=f"{STAGING_PREFIX}{os.getpid()}-", dir=folder))
    except OSError as error:
        raise InputError(f"{folder}: cannot write in the folder ({error.strerror})") from None
    try:
        yield staging
    finally:
        shutil.rmtree(staging, ignore_errors=True)


def residue_lines(analysis: FileAnalysis) -> str:
    """The ``residues.csv`` rows of one file: the residue, its class and ``|Cα − C^r|`` (Å, 3
    decimals, empty beyond a curve's lowest level) in every depth column."""
    head = f"{_field(str(analysis.path))},{_field(analysis.entry)}"
    number = ",".join(["%.3f"] * analysis.deviations.shape[1])
    return "".join(
        f"{head},{_field(chain)},{curve},{resseq},{_field(icode)},{_field(resname)},{ss},{ss_class},"
        + (number % tuple(values)).replace("nan", "") + "\n"
        for values, chain, curve, resseq, icode, resname, ss, ss_class in zip(
            analysis.deviations.tolist(), analysis.chain.tolist(), analysis.curve.tolist(), analysis.resseq.tolist(),
            analysis.icode.tolist(), analysis.resname.tolist(), analysis.ss.tolist(), analysis.ss_class.tolist(),
        )
    )


def summary_csv(rows: list[SummaryRow]) -> str:
    """``ribbon,mode,depth,class,n_residues,rms,sd`` with rms and SD in Å."""
    return _csv_text([SUMMARY_COLUMNS] + [
        (r.ribbon, r.mode, f"{r.depth:g}", r.ss_class, r.n_residues, f"{r.rms:.4f}", f"{r.sd:.4f}") for r in rows
    ])


def summary_text(pooled: PooledStatistics, skipped: list[SkippedFile], folder: Path) -> str:
    """The report printed at the end of ``analyze``."""
    rows = pooled.rows()
    lines = [
        f"analysed {pooled.n_files} file(s), {pooled.n_curves} curves, {pooled.n_residues} residues"
        + (f"; skipped {len(skipped)} (listed in {folder / 'skipped.csv'})" if skipped else ""),
        f"wrote {', '.join(str(folder / name) for name in OUTPUTS)}",
        f"{pooled.n_residues_without_records} residues in {pooled.n_files_without_records} file(s) without "
        "HELIX/SHEET records: " + ("counted only in class 'all'" if pooled.options.ss is SSPolicy.RECORDS
                                   else "helix/sheet/other computed by DSSP"),
    ]
    if not rows:
        return "\n".join(lines)
    stat = {(r.ribbon, r.mode, r.depth, r.ss_class): r for r in rows}

    def rms(ribbon: str, mode: str, depth: float, name: str = "all", width: int = 8) -> str:
        row = stat.get((ribbon, mode, float(depth), name))
        return f"{row.rms:{width}.2f}" if row else f"{'–':>{width}}"

    lines += ["", "pooled rms |Cα − C^r| in Å (SD of the distances) by decomposition step (depth)",
              f"{'':<17}{'peptide-plane ribbon':^45}{'Cα ribbon':>11}",
              f"{'mode':<11}{'depth':>6}{'all (SD)':>14}{'helix':>8}{'sheet':>8}{'other':>8}{'residues':>10}{'all':>8}"]
    for mode in MODES:
        for depth in sorted({r.depth for r in rows if r.mode == mode}):
            every = stat.get(("peptide", mode, depth, "all"))
            first = f"{every.rms:.2f} ({every.sd:.2f})" if every else "–"
            lines.append(f"{mode:<11}{depth:>6g}{first:>14}" + "".join(rms("peptide", mode, depth, c) for c in CLASSES[1:])
                         + f"{every.n_residues if every else 0:>10}" + rms("calpha", mode, depth))
    lines += ["", f"{'':<42}{'peptide':>8}{'Cα':>8}   Carson 1996 (230 proteins)"]
    for depth, paper in PAPER.items():
        lines.append(f"{f'rms at 1/{2**depth} of the segments (depth {depth}), Å':<42}"
                     f"{rms('peptide', 'integer', depth)}{rms('calpha', 'integer', depth)}   {paper}")
    crossings = "".join(f"{c:8.2f}" if c is not None else f"{'never':>8}"
                        for c in (rms_crossing(rows, CA_CA, ribbon) for ribbon in ("peptide", "calpha")))
    lines.append(f"{f'fractional depth where the rms passes {CA_CA} Å':<42}{crossings}   between 2.0 and 3.0")
    lines.append("(the crossing is interpolated linearly between the fractional depths computed)")
    return "\n".join(lines)


def plot_fig7(rows: list[SummaryRow], path: Path) -> None:
    """Carson's Fig. 7: rms ± 1 SD of ``|Cα − C^r|`` against decomposition step, one series
    per class; integer and fractional modes side by side, one row per ribbon."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    figure = Figure(figsize=(11, 8), layout="constrained")
    FigureCanvasAgg(figure)
    axes = figure.subplots(len(RIBBONS), len(MODES), sharey=True, squeeze=False)
    for i, ribbon in enumerate(r.value for r in RIBBONS):
        for k, mode in enumerate(MODES):
            ax = axes[i][k]
            step = min(np.diff(sorted({r.depth for r in rows if r.mode == mode})), default=1.0)
            for c, name in enumerate(CLASSES):
                series = sorted((r.depth, r.rms, r.sd) for r in rows if (r.ribbon, r.mode, r.ss_class) == (ribbon, mode, name))
                if series:
                    x, y, sd = np.array(series).T
                    ax.errorbar(x + (c - 1.5) * 0.1 * step, y, yerr=sd, fmt="_", markersize=10, capsize=2,
                                elinewidth=1, color=CLASS_COLOURS[name], label=name)
            ax.axhline(CA_CA, color="0.6", linestyle="--", linewidth=0.8)
            ax.text(0.01, CA_CA, f" Cα–Cα {CA_CA} Å", va="bottom", color="0.4", fontsize=8,
                    transform=ax.get_yaxis_transform())
            ax.set_title(f"{RIBBON_TITLES[ribbon]}, {mode} levels "
                         + ("(level J − step: 1/2, 1/4, … of the segments)" if mode == "integer" else "(level log2 N − step)"),
                         fontsize=10)
            ax.set_xlabel("decomposition step")
            ax.grid(alpha=0.3)
        axes[i][0].set_ylabel("|Cα − $C^r$| (Å): rms ± 1 SD")
    if rows:
        axes[0][0].legend(title="residues", fontsize=8)
    figure.suptitle("Distance of the Cα to the low-resolution curve (after Carson 1996, Fig. 7)")
    figure.savefig(path, dpi=110, format="png")


# --------------------------------------------------------------------------- helpers


@functools.lru_cache(maxsize=None)
def _field(text: str) -> str:
    """``text`` as one CSV field (quoted only when it needs to be; see :func:`_cell`)."""
    text = _cell(text)
    if any(c in text for c in ',"\r\n'):
        return '"' + text.replace('"', '""') + '"'
    return text


def _named(path: Path) -> str:
    """``path`` as text that any stream takes and no terminal acts on (a byte that is not UTF-8
    escaped as :data:`NAMES` says, a control character as :func:`app.errors.printable` does)."""
    return printable(str(path).encode("utf-8", NAMES).decode("utf-8"))


def _cell(text: str) -> str:
    """Text a spreadsheet shows as text: a leading ``=``, ``+``, ``-``, ``@``, tab or CR would
    start a formula, so such text gets a leading apostrophe (OWASP's advice on CSV injection)."""
    return "'" + text if text[:1] in FORMULA_STARTS else text


def _csv_text(rows: list[tuple]) -> str:
    out = io.StringIO()
    csv.writer(out, lineterminator="\n").writerows(rows)
    return out.getvalue()


