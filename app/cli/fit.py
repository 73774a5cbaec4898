"""The headless ``fit`` and ``morph`` commands: a model moved onto another conformation, coarse
to fine, with the wavelet levels as the unknowns (:mod:`core.fitting`)."""

from __future__ import annotations

import argparse
import json
import re
from pathlib import Path

import numpy as np

from app.cli.structure import chain_segments, load, model_argument
from app.errors import InputError
from core.analysis.compare import PAIRINGS
from core.analysis.superpose import superpose
from core.fitting.coarse_to_fine import Pairs
from core.fitting.conformation import SAME_FOLD, ConformationFit, fit_conformation, fold_similarity, pair_segments
from core.fitting.morph import morph_frames
from core.geometry.validation import validate
from core.protein.model import EditableModel
from core.protein.structure import Structure, ca_rows
from core.protein.writing import write_models

DEFAULT_LEVELS = (0, 6)
MAX_FRAMES = 1000
CHECKED = (("peptide_bond", "bad peptide bonds"), ("ca_ca", "bad Cα–Cα"), ("clash", "clashes"),
           ("ramachandran", "Ramachandran outliers"))


def levels(text: str) -> tuple[int, int]:
    """``FROM-TO`` (integer levels, FROM ≤ TO ≤ 30) as a pair."""
    match = re.fullmatch(r"\s*(\d+)\s*-\s*(\d+)\s*", text)
    if match is None or not int(match[1]) <= int(match[2]) <= 30:
        raise argparse.ArgumentTypeError(f"expected integer levels FROM-TO with FROM <= TO <= 30; got {text!r}")
    return int(match[1]), int(match[2])


def _common_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--levels", type=levels, default=DEFAULT_LEVELS, metavar="FROM-TO",
                        help=f"levels fitted in turn, coarse first (default {DEFAULT_LEVELS[0]}-{DEFAULT_LEVELS[1]}; "
                             "higher ones than a segment has are its finest)")
    parser.add_argument("--pairing", choices=PAIRINGS, default="auto",
                        help="how residues are paired, as in compare (default auto)")
    parser.add_argument("--overwrite", action="store_true", help="replace OUT if it exists")


def fit_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", type=Path, metavar="MODEL", help="structure to move (PDB or mmCIF, optionally gzipped)")
    model_argument(parser)
    parser.add_argument("--to", required=True, type=Path, metavar="TARGET", help="the structure to move it onto")
    parser.add_argument("--chain", metavar="ID", help="chain of MODEL to fit (default: its first protein chain)")
    parser.add_argument("--target-chain", metavar="ID", help="chain of TARGET (default: its first protein chain)")
    _common_arguments(parser)
    parser.add_argument("--no-regularize", dest="regularize", action="store_false",
                        help="leave the residues as the fit remaps them (peptide junctions may stretch)")
    parser.add_argument("-o", "--output", required=True, type=Path, metavar="OUT",
                        help="output file; PDB or mmCIF by the extension (.pdb, .cif, optionally .gz)")
    parser.add_argument("--json", action="store_true", help="print a JSON object instead of text")


def run_fit(args: argparse.Namespace) -> int:
    model_structure, target = load(args.file, args.model), load(args.to)
    model, pairs, pairing, rows = _paired(model_structure, args.chain, target, args.target_chain, args.pairing)
    before = validate(model_structure, model.coords).counts
    result = _fit(model, pairs, args.levels, args.regularize)
    fits = result.levels
    after = validate(model_structure, model.coords).counts
    rmsd = superpose(model.coords[rows], np.concatenate([p.target for p in pairs])).rmsd
    try:
        written = model.save(args.output, overwrite=args.overwrite)
    except FileExistsError as error:
        raise InputError(f"{error} (pass --overwrite to replace it)") from None
    except (ValueError, OSError) as error:
        raise InputError(str(error)) from None
    report = {
        "model": str(args.file), "target": str(args.to), "pairing": pairing,
        "pairs": sum(len(p.residues) for p in pairs),
        "levels": [{"level": f.level, "control_points": f.control_points, "rmsd": round(f.score, 4),
                    "seconds": round(f.seconds, 4)} for f in fits],
        "dropped_levels": result.dropped, "regularized": args.regularize, "rmsd": round(rmsd, 4),
        "validation": {kind: {"before": before[kind], "after": after[kind]} for kind, _ in CHECKED},
        "output": str(written),
    }
    if args.json:
        print(json.dumps(report, indent=2))
        return 0
    print(f"{report['pairs']} residue pairs ({pairing}); Cα rmsd to the target after each level:")
    for f in fits:
        print(f"  level {f.level}: {f.control_points:4d} control points, Cα rmsd {f.score:6.3f} Å, {f.seconds:6.2f} s")
    if result.dropped:
        print(f"  levels {', '.join(map(str, result.dropped))} undone: the regularized model kept more bad peptide "
              "junctions than the input (the target's backbone differs at that detail)")
    done = "regularized" if args.regularize else "not regularized"
    print(f"{done}: Cα rmsd {rmsd:.3f} Å; " + ", ".join(f"{before[k]} -> {after[k]} {name}" for k, name in CHECKED))
    print(f"wrote {written}")
    return 0


def morph_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file_a", type=Path, metavar="A", help="the first conformation (PDB or mmCIF)")
    parser.add_argument("file_b", type=Path, metavar="B", help="the last conformation")
    parser.add_argument("--chains", metavar="X:Y", help="chain of A and chain of B (default: the first of each)")
    parser.add_argument("--frames", type=int, default=30, metavar="N",
                        help="frames after A, shared among the levels by how far each moves, at least one per level "
                             f"(default 30, at most {MAX_FRAMES})")
    _common_arguments(parser)
    parser.add_argument("-o", "--output", required=True, type=Path, metavar="MOVIE",
                        help="multi-model output, one model per frame: .pdb or .cif (optionally .gz)")


def run_morph(args: argparse.Namespace) -> int:
    if not 1 <= args.frames <= MAX_FRAMES:
        raise InputError(f"--frames must be between 1 and {MAX_FRAMES}; got {args.frames}")
    chain_a, chain_b = _chains(args.chains)
    start = load(args.file_a)
    model, pairs, pairing, _ = _paired(start, chain_a, load(args.file_b), chain_b, args.pairing)
    fits = _fit(model, pairs, args.levels, regularize=False).levels
    frames = morph_frames(EditableModel(start), fits, args.frames)
    try:
        written = write_models(start, frames, args.output, overwrite=args.overwrite)
    except FileExistsError as error:
        raise InputError(f"{error} (pass --overwrite to replace it)") from None
    except (ValueError, OSError) as error:
        raise InputError(str(error)) from None
    print(f"{sum(len(p.residues) for p in pairs)} residue pairs ({pairing}); levels "
          + ", ".join(f"{f.level} ({f.score:.2f} Å)" for f in fits))
    print(f"wrote {len(frames)} frames to {written}")
    return 0


def _chains(text: str | None) -> tuple[str | None, str | None]:
    if text is None:
        return None, None
    if text.count(":") != 1:
        raise InputError(f"--chains takes X:Y (a chain of A and a chain of B); got {text!r}")
    a, b = text.split(":")
    return a, b


def _paired(
    structure: Structure, chain: str | None, target: Structure, target_chain: str | None, pairing: str
) -> tuple[EditableModel, list[Pairs], str, np.ndarray]:
    """The model of ``structure``, its chain's residues paired with the target chain's, the
    pairing used and the Cα rows of the paired residues."""
    if not structure.segments or not target.segments:
        missing = structure if not structure.segments else target
        raise InputError(f"{missing.path}: no protein chain to fit")
    numbers = chain_segments(structure, structure.segments[0].chain if chain is None else chain)
    target_numbers = chain_segments(target, target.segments[0].chain if target_chain is None else target_chain)
    model = EditableModel(structure)
    try:
        pairs, used = pair_segments(model, numbers, [target.segments[k] for k in target_numbers], pairing)
    except ValueError as error:
        raise InputError(f"cannot pair the residues: {error}") from None
    if sum(len(p.residues) for p in pairs) < 3:
        raise InputError("fewer than 3 residue pairs between the chains: nothing to fit (try --pairing structure)")
    similarity = fold_similarity(model, pairs)
    if similarity < SAME_FOLD:
        raise InputError(f"{target.path} is another fold (TM-score {similarity:.2f} < {SAME_FOLD} over "
                         f"{sum(len(p.residues) for p in pairs)} {used}-paired residues): nothing to fit onto")
    ca = ca_rows(structure)
    rows = np.concatenate([ca[structure.segments[p.segment].residue_index[p.residues]] for p in pairs])
    return model, pairs, used, rows


def _fit(model: EditableModel, pairs: list[Pairs], bounds: tuple[int, int], regularize: bool) -> ConformationFit:
    try:
        return fit_conformation(model, pairs, range(bounds[0], bounds[1] + 1), regularize=regularize)
    except ValueError as error:
        raise InputError(str(error)) from None
