"""Headless database commands: ``analyze`` (Carson's Fig. 7 over many files) and ``compare``
(two chains superposed, fits on less data judged on a core set). Core does the science;
this module reads arguments, runs files in parallel, writes CSV/JSON/PNG and prints.

Output formats are a contract for other programs: the columns of ``summary.csv``,
``residues.csv`` and ``skipped.csv``, and the field names of ``compare --json``.
"""

from __future__ import annotations

import argparse
import contextlib
import csv
import ctypes
import functools
import io
import json
import multiprocessing
import os
import re
import shutil
import signal
import socket
import struct
import sys
import tempfile
import urllib.parse
from collections.abc import Callable, Iterator
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path
from typing import TypeVar

import numpy as np
from tqdm import tqdm

from app.arguments import bounded, bounded_list
from app.cli.structure import load
from app.errors import InputError
from core.analysis.compare import PAIRINGS, Comparison, compare_chains
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
from core.protein.ribbon import RibbonKind
from core.protein.structure import BackboneSegment, Structure

SUMMARY_COLUMNS = ("ribbon", "mode", "depth", "class", "n_residues", "rms", "sd")
RESIDUE_COLUMNS = ("file", "entry", "chain", "curve", "resseq", "icode", "resname", "ss", "class")
OUTPUTS = ("residues.csv", "summary.csv", "skipped.csv", "fig7.png")
STAGING_PREFIX = ".analyze-"
"""Outputs are written into a new folder ``OUTDIR/.analyze-PID-XXXXXXXX``, then moved into place."""
DASK_TIMEOUT = 10.0
"""Seconds to connect to a Dask scheduler and hear its greeting."""
DASK_FRAME = struct.Struct("<Q")
"""A Dask message starts with its length: 8 bytes, little-endian."""
DASK_GREETING_MAX = 1 << 20
"""Bytes a scheduler's greeting (its handshake) may take: a few hundred in practice."""
PR_SET_PDEATHSIG = 1
"""prctl(2): the signal a process gets when its parent ends."""
FORMULA_STARTS = ("=", "+", "-", "@", "\t", "\r")
STRUCTURE_SUFFIXES = (".pdb", ".ent", ".cif", ".mmcif")
CA_CA = 3.8
"""Ideal Cα–Cα distance (Å): the rms a coarse curve should stay below (Carson 1996)."""
PAPER = {2: 2.1, 3: 3.3}
"""Carson's pooled rms (Å) of the peptide-plane ribbon at integer depths 2 and 3."""
CLASS_COLOURS = {"all": "black", "helix": "tab:red", "sheet": "tab:blue", "other": "tab:gray"}
RIBBON_TITLES = {"peptide": "peptide-plane ribbon", "calpha": "Cα ribbon"}
T = TypeVar("T")
Outcome = tuple[FileAnalysis | SkippedFile, str]
"""A file's analysis (or why it was skipped) and its ``residues.csv`` rows."""


# --------------------------------------------------------------------------- analyze


def batch_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the files of a run over many structures and where it runs (:func:`run_tasks`):
    ``PATH...``, ``--jobs`` and ``--scheduler``."""
    parser.add_argument("paths", nargs="+", type=Path, metavar="PATH",
                        help="structure files or folders (searched recursively for .pdb/.ent/.cif/.mmcif, optionally .gz)")
    parser.add_argument("--jobs", type=bounded(int, 1, 4096), default=len(os.sched_getaffinity(0)), metavar="N",
                        help="worker processes (default: all cores)")
    parser.add_argument("--scheduler", nargs="?", const="local", metavar="ADDRESS",
                        help="run on a Dask cluster (e.g. tcp://host:8786); without ADDRESS, a local cluster "
                        "of --jobs workers (needs the 'cluster' extra: dask[distributed])")


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
    with (_staging(args.output) as staging, (staging / "residues.csv").open("w", encoding="utf-8") as table,
          tqdm(total=len(paths), unit="file", desc="analysing", file=sys.stderr, mininterval=0.5) as progress):
        table.write(",".join(RESIDUE_COLUMNS + tuple(c.name for c in options.columns)) + "\n")
        task = functools.partial(analyse_file, options=options)
        for index, (result, lines) in run_tasks(task, paths, args.jobs, args.scheduler, _failed_file):
            progress.update()
            if isinstance(result, SkippedFile):
                progress.write(f"skipped {result.path}: {result.reason}", file=sys.stderr)
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
            _csv_text([("file", "reason")] + [(_cell(str(s.path)), _cell(s.reason)) for s in skipped]), encoding="utf-8")
        plot_fig7(rows, staging / "fig7.png")
        for name in OUTPUTS:  # all four at once, at the end: a killed run leaves the old set
            os.replace(staging / name, args.output / name)
    print(summary_text(pooled, skipped, args.output))
    if not pooled.n_files:
        raise InputError(f"no file could be analysed: all {len(skipped)} were skipped "
                         f"(see {args.output / 'skipped.csv'})")
    return 0


def structure_paths(paths: list[Path]) -> list[Path]:
    """The files named, and the structure files inside the folders named (sorted, recursive)."""
    found: list[Path] = []
    for path in paths:
        if path.is_dir():
            found += sorted(
                p for p in path.rglob("*")
                if p.is_file() and not p.name.startswith(".")
                and p.name.lower().removesuffix(".gz").endswith(STRUCTURE_SUFFIXES)
            )
        else:
            found.append(path)  # a file that cannot be read is reported and skipped later
    if not found:
        raise InputError(f"no structure files (.pdb, .ent, .cif, .mmcif, optionally .gz) in {', '.join(map(str, paths))}")
    return found


def run_tasks(task: Callable[[Path], T], paths: list[Path], jobs: int, scheduler: str | None,
              failed: Callable[[Path, str], T]) -> Iterator[tuple[int, T]]:
    """(index, ``task(path)``) of every path, in order of completion: in this process
    (``jobs`` 1), in ``jobs`` worker processes, or on the Dask cluster at ``scheduler``
    ('local': a private one of ``jobs`` workers). ``task`` must pickle (a top-level function,
    or a partial of one); a worker that dies gives ``failed(path, reason)``."""
    if scheduler is not None:
        yield from _run_dask(task, paths, jobs, scheduler, failed)
    elif jobs == 1 or len(paths) == 1:
        for index, path in enumerate(paths):
            yield index, task(path)
    else:
        context = multiprocessing.get_context("spawn")  # no fork of a threaded parent; workers are its children
        with ProcessPoolExecutor(min(jobs, len(paths)), mp_context=context, initializer=_end_with_parent,
                                 initargs=(os.getpid(),)) as pool:
            futures = {pool.submit(task, path): index for index, path in enumerate(paths)}
            try:
                for future in as_completed(futures):
                    index = futures.pop(future)  # hold no finished result longer than needed
                    yield index, _outcome(future, paths[index], failed)
            except BaseException:  # Ctrl+C or an error: drop the files not started yet
                pool.shutdown(cancel_futures=True)
                raise


def _run_dask(task: Callable[[Path], T], paths: list[Path], jobs: int, address: str,
              failed: Callable[[Path, str], T]) -> Iterator[tuple[int, T]]:
    try:
        import dask
        from dask.distributed import Client, LocalCluster, as_completed as dask_completed
    except ImportError:
        raise InputError("--scheduler needs Dask: pip install 'dask[distributed]' (the 'cluster' extra)") from None
    with contextlib.ExitStack() as stack:
        try:
            if address == "local":
                client = _local_client(stack, LocalCluster, Client, jobs, dask)
            else:
                _check_scheduler(address)
                client = stack.enter_context(Client(address, timeout=DASK_TIMEOUT))
        except (OSError, ValueError, TimeoutError) as error:
            raise InputError(f"cannot reach the Dask scheduler {address}: {error}") from None
        futures = client.map(task, paths, pure=False)
        index = {future.key: k for k, future in enumerate(futures)}
        completed = dask_completed(futures)
        del futures  # a result is released on the cluster once it has been handled
        for future in completed:
            k = index.pop(future.key)
            yield k, _outcome(future, paths[k], failed)


def _local_client(stack: contextlib.ExitStack, local_cluster: type, client: type, jobs: int, dask: object) -> object:
    """A client of a cluster on this machine that only this process can use: TLS with a
    certificate made for this run (no other user can submit tasks to it), on 127.0.0.1,
    with the HTTP servers of the scheduler and the workers stopped."""
    try:
        from distributed.security import Security

        security = Security.temporary()
    except ImportError:
        raise InputError("--scheduler needs the 'cryptography' package for a private local cluster: "
                         "pip install 'ribbonwave[cluster]'") from None
    stack.enter_context(dask.config.set({"distributed.scheduler.http.routes": [],
                                         "distributed.worker.http.routes": []}))
    cluster = stack.enter_context(local_cluster(
        n_workers=jobs, threads_per_worker=1, processes=True, protocol="tls", security=security, host="127.0.0.1",
        dashboard_address=None, worker_dashboard_address=None))
    cluster.scheduler.http_server.stop()
    connected = stack.enter_context(client(cluster, security=security, timeout=DASK_TIMEOUT))
    connected.run(_stop_http_server)
    return connected


def _stop_http_server(dask_worker: object) -> None:
    """Run on each worker of the local cluster: no HTTP endpoint (metrics, health) on it."""
    dask_worker.http_server.stop()


def _check_scheduler(address: str) -> None:
    """Refuse an address that is not ``tcp://HOST:PORT``, and a server there that does not
    greet like a Dask scheduler within DASK_TIMEOUT (Dask would take any 8 bytes it sends
    for the length of a message, and allocate it)."""
    parts = urllib.parse.urlsplit(address if "://" in address else f"tcp://{address}")
    try:
        port = parts.port
    except ValueError:
        port = None
    if parts.scheme != "tcp" or not parts.hostname or port is None or parts.path not in ("", "/"):
        raise InputError(f"--scheduler {address}: expected tcp://HOST:PORT (a scheduler with TLS needs its "
                         "credentials, which analyze does not take)")
    try:
        with socket.create_connection((parts.hostname, port), timeout=DASK_TIMEOUT) as connection:
            connection.settimeout(DASK_TIMEOUT)
            greeting = b""
            while len(greeting) < DASK_FRAME.size:
                chunk = connection.recv(DASK_FRAME.size - len(greeting))
                if not chunk:
                    break
                greeting += chunk
    except TimeoutError:
        raise InputError(f"--scheduler {address}: the server there does not greet like a Dask scheduler "
                         f"(nothing within {DASK_TIMEOUT:g} s)") from None
    except OSError as error:
        raise InputError(f"cannot reach the Dask scheduler {address}: {error.strerror or error}") from None
    if len(greeting) < DASK_FRAME.size or not 0 < DASK_FRAME.unpack(greeting)[0] <= DASK_GREETING_MAX:
        raise InputError(f"--scheduler {address}: the server there is not a Dask scheduler")


def analyse_file(path: Path, options: AnalysisOptions) -> Outcome:
    """The task run by a worker: the rows are formatted there too, in parallel."""
    result = analyse_path(path, options)
    return result, residue_lines(result) if isinstance(result, FileAnalysis) else ""


def _end_with_parent(parent: int) -> None:
    """In a worker (Linux): be killed when ``analyze`` (process ``parent``, which started it)
    ends, so that killing ``analyze`` leaves no worker behind."""
    if sys.platform.startswith("linux"):
        ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGKILL)
        if os.getppid() != parent:  # it ended while this worker started
            os._exit(1)


def _outcome(future, path: Path, failed: Callable[[Path, str], T]) -> T:
    """A finished task's outcome; a worker that died gives ``failed``'s, not a failed run."""
    try:
        return future.result()
    except Exception as error:  # noqa: BLE001 - e.g. a worker killed while reading this file
        return failed(path, f"worker failed ({type(error).__name__}: {error})")


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
        if stale.is_dir() and not stale.is_symlink() and pid.isdigit() and not _alive(int(pid)):
            shutil.rmtree(stale, ignore_errors=True)


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        pass  # another user's process
    return True


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


# --------------------------------------------------------------------------- compare


def compare_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file_a", type=Path, metavar="A", help="structure file (PDB or mmCIF, optionally gzipped)")
    parser.add_argument("file_b", type=Path, nargs="?", metavar="B", help="second structure file (default: A)")
    parser.add_argument("--chains", type=_chain_pair, metavar="X:Y",
                        help="chain X of A and chain Y of B (default: the first two chains of A when B is not "
                        "given, else the first chain of each)")
    parser.add_argument("--core", metavar="RESIDUES",
                        help="core set as residue numbers of chain X, e.g. 5-20,31,40A (default: the pairs within "
                        "--core-cutoff after an iterative fit)")
    parser.add_argument("--core-cutoff", type=bounded(float, 0.01, 50), default=1.0, metavar="Å",
                        help="distance cutoff of the iterative core set (default %(default)g Å)")
    parser.add_argument("--steps", type=bounded_list(1, 1000), default=(2, 4, 8, 16), metavar="M,...",
                        help="fit on every M-th paired Cα from every offset (default 2,4,8,16)")
    parser.add_argument("--depths", type=bounded_list(1, 16), default=(1, 2, 3, 4), metavar="K,...",
                        help="fit on the residue points C^r of the curves at level J − K (default 1,2,3,4)")
    parser.add_argument("--ribbon", choices=[k.value for k in RibbonKind], default=RibbonKind.PEPTIDE.value,
                        help="curve of the C^r fits: peptide-plane ribbon (default) or the curve through the Cα")
    parser.add_argument("--termini", choices=[t.value for t in Termini], default="atoms",
                        help="terminal ribbon points: N and C atoms when present (default) or Cα extrapolations")
    parser.add_argument("--pairing", choices=PAIRINGS, default="auto",
                        help="pair residues by number, by sequence alignment or by structural alignment "
                             "(auto: by number when it agrees, else by structure)")
    parser.add_argument("--json", action="store_true", help="print a JSON object instead of the table")


def run_compare(args: argparse.Namespace) -> int:
    structure_a = load(args.file_a)
    structure_b = load(args.file_b) if args.file_b is not None else structure_a
    name_a, name_b = args.chains or _default_chains(structure_a, structure_b, args.file_b is None)
    chain_a, chain_b = _chain(structure_a, name_a), _chain(structure_b, name_b)
    core = None if args.core is None else _core_mask(chain_a, args.core)
    try:
        result = compare_chains(chain_a, chain_b, core_residues=core, cutoff=args.core_cutoff, steps=args.steps,
                                depths=args.depths, ribbon=args.ribbon, termini=args.termini, pairing=args.pairing)
    except ValueError as error:
        raise InputError(str(error)) from None
    report = comparison_report(result, f"{args.file_a} chain {name_a}",
                               f"{args.file_b or args.file_a} chain {name_b}")
    print(json.dumps(report, indent=2) if args.json else comparison_text(report))
    return 0


def comparison_report(result: Comparison, label_a: str, label_b: str) -> dict:
    """The ``compare --json`` object (lengths in Å)."""
    return {
        "chain_a": label_a,
        "chain_b": label_b,
        "length_a": result.length_a,
        "length_b": result.length_b,
        "pairing": result.pairing,
        "n_pairs": result.n_pairs,
        "rms_all": round(result.rms_all, 4),
        "tm_score": round(result.tm_score, 4),
        "tm_score_length": result.length_a,
        "tm_score_d0": round(result.d0, 4),
        "tm_score_note": "superposition on all paired Cα; normalised by the length of the first chain",
        "tm_score_a": round(result.match.tm_score_a, 4),
        "tm_score_b": round(result.match.tm_score_b, 4),
        "n_aligned": result.match.n_aligned,
        "rms_aligned": round(result.match.rms_aligned, 4),
        "identity": round(result.match.identity, 4),
        "same_fold": result.match.same_fold,
        "core_rule": result.core_rule,
        "n_core": result.n_core,
        "rms_core": round(result.rms_core, 4) if result.fits else None,
        "fits": [
            {"points": f.points, "depth": f.depth, "every": f.every, "start": f.start, "n_fit": f.n_fit,
             "rms_core": round(f.rms_core, 4)}
            for f in result.fits
        ],
    }


def comparison_text(report: dict) -> str:
    """The ``compare`` table."""
    lines = [
        f"{report['chain_a']} ({report['length_a']} residues) vs {report['chain_b']} ({report['length_b']} residues)",
        f"{report['n_pairs']} residue pairs by {report['pairing']}",
        f"fit on all paired Cα: rms {report['rms_all']:.3f} Å; TM-score {report['tm_score']:.4f} (of this "
        f"superposition, normalised by the length of the first chain, {report['tm_score_length']} residues; "
        f"d0 = {report['tm_score_d0']:.2f} Å)",
        f"structural match: TM-score {report['tm_score_a']:.4f} (normalised by the first chain, "
        f"{report['length_a']} residues), {report['tm_score_b']:.4f} (by the second, {report['length_b']}); "
        f"{report['n_aligned']} aligned pairs, rms {report['rms_aligned']:.3f} Å, sequence identity "
        f"{100 * report['identity']:.1f}%",
        "same fold (TM-score >= 0.5)" if report["same_fold"] else "different folds (TM-score < 0.5)",
    ]
    if not report["fits"]:
        return "\n".join(lines + [f"core set: {report['n_core']} pairs ({report['core_rule']}): too few for the "
                                   "fits on fewer data (at least 3 are needed)"])
    lines += [
        f"core set: {report['n_core']} pairs ({report['core_rule']}); best fit on the core: rms {report['rms_core']:.3f} Å",
        "",
        "fits on fewer data, each judged by the rms over the core set (Å):",
        f"{'fitted on':<20}{'every':>6}{'n fit':>7}{'min':>8}{'mean':>8}{'max':>8}   by start 1, 2, ...",
    ]
    groups: dict[tuple[str, int, int], list[dict]] = {}
    for fit in report["fits"]:
        groups.setdefault((fit["points"], fit["depth"], fit["every"]), []).append(fit)
    for (points, depth, every), fits in groups.items():
        rms = [f["rms_core"] for f in fits]
        name = "Cα" if points == "CA" else f"C^r at level J − {depth}"
        lines.append(f"{name:<20}{every:>6}{fits[0]['n_fit']:>7}{min(rms):8.3f}{np.mean(rms):8.3f}{max(rms):8.3f}   "
                     + " ".join(f"{r:.3f}" for r in rms))
    return "\n".join(lines)


def _default_chains(a: Structure, b: Structure, same_file: bool) -> tuple[str, str]:
    names_a = list(dict.fromkeys(s.chain for s in a.segments))
    if not same_file:
        return names_a[0], next(s.chain for s in b.segments)
    if len(names_a) < 2:
        raise InputError(f"{a.path}: has one protein chain ({names_a[0]}); give a second file or --chains X:Y")
    return names_a[0], names_a[1]


def _chain(structure: Structure, name: str) -> list[BackboneSegment]:
    segments = [s for s in structure.segments if s.chain == name]
    if not segments:
        chains = ", ".join(dict.fromkeys(s.chain for s in structure.segments))
        raise InputError(f"{structure.path}: no protein chain {name!r} (chains: {chains})")
    return segments


def _core_mask(chain: list[BackboneSegment], text: str) -> np.ndarray:
    """Chain residues named by a list such as ``5-20,31,40A`` (ranges by residue number)."""
    resseq = np.concatenate([s.resseq for s in chain])
    labels = [f"{n}{i}" for s in chain for n, i in zip(s.resseq.tolist(), s.icode.tolist())]
    mask = np.zeros(len(resseq), dtype=bool)
    for item in text.split(","):
        item = item.strip()
        if match := re.fullmatch(r"(-?\d+)-(-?\d+)", item):
            picked = (resseq >= int(match[1])) & (resseq <= int(match[2]))
        else:
            picked = np.array([label == item for label in labels], dtype=bool)
        if not picked.any():
            raise InputError(f"--core: no residue {item!r} in chain {chain[0].chain}")
        mask |= picked
    return mask


# --------------------------------------------------------------------------- helpers


def _chain_pair(text: str) -> tuple[str, str]:
    parts = text.split(":")
    if len(parts) != 2 or not all(parts):
        raise argparse.ArgumentTypeError(f"expected two chain ids X:Y; got {text!r}")
    return parts[0], parts[1]


@functools.lru_cache(maxsize=None)
def _field(text: str) -> str:
    """``text`` as one CSV field (quoted only when it needs to be; see :func:`_cell`)."""
    text = _cell(text)
    if any(c in text for c in ',"\r\n'):
        return '"' + text.replace('"', '""') + '"'
    return text


def _cell(text: str) -> str:
    """Text a spreadsheet shows as text: a leading ``=``, ``+``, ``-``, ``@``, tab or CR would
    start a formula, so such text gets a leading apostrophe (OWASP's advice on CSV injection)."""
    return "'" + text if text[:1] in FORMULA_STARTS else text


def _csv_text(rows: list[tuple]) -> str:
    out = io.StringIO()
    csv.writer(out, lineterminator="\n").writerows(rows)
    return out.getvalue()


