"""``ribbonwave compare``: two chains superposed, fits on less data judged on a core set.
Core does the science (:mod:`core.analysis.compare`); this module reads arguments and prints
a table or, with ``--json``, an object whose field names are a contract for other programs.
"""

from __future__ import annotations

import argparse
import json
import re
from pathlib import Path

import numpy as np

from app.arguments import bounded, bounded_list
from app.cli.structure import load
from app.errors import InputError
from core.analysis.compare import PAIRINGS, Comparison, compare_chains
from core.analysis.database import Termini
from core.protein.ribbon import RibbonKind
from core.protein.structure import BackboneSegment, Structure


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
        "paired_tm_score": round(result.tm_score, 4),
        "paired_tm_score_length": result.length_a,
        "paired_tm_score_d0": round(result.d0, 4),
        "paired_tm_score_note": "of the superposition on all paired Cα (rms_all), normalised by the length of the "
                                "first chain; not the structural match's TM-score (tm_score)",
        "tm_score": round(result.match.tm_score_a, 4),
        "tm_score_b": round(result.match.tm_score_b, 4),
        "tm_score_note": "the structural match, as TM-align scores it: the TM-score of the pairs after TM-align's "
                         "superposition search, normalised by the first chain (tm_score_b: by the second); "
                         "TM-align's own figure when the pairing is by structure",
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
        f"fit on all paired Cα: rms {report['rms_all']:.3f} Å; paired TM-score {report['paired_tm_score']:.4f} "
        f"(of this superposition, normalised by the length of the first chain, {report['paired_tm_score_length']} "
        f"residues; d0 = {report['paired_tm_score_d0']:.2f} Å)",
        f"structural match: TM-score {report['tm_score']:.4f} (normalised by the first chain, "
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


def _chain_pair(text: str) -> tuple[str, str]:
    parts = text.split(":")
    if len(parts) != 2 or not all(parts):
        raise argparse.ArgumentTypeError(f"expected two chain ids X:Y; got {text!r}")
    return parts[0], parts[1]
