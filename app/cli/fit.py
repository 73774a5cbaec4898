"""The headless ``fit`` and ``morph`` commands: a model moved onto another conformation or into
a density map, coarse to fine, with the wavelet levels as the unknowns (:mod:`core.fitting`)."""

from __future__ import annotations

import argparse
import json
import re
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np
from tqdm import tqdm

from app.arguments import bounded
from app.cli.structure import chain_segments, checked_output, load, model_argument
from app.errors import InputError
from core.analysis.compare import PAIRINGS
from core.analysis.superpose import superpose
from core.fitting.coarse_to_fine import Pairs
from core.fitting.conformation import (
    SAME_FOLD,
    fit_conformation,
    fold_similarity,
    pair_segments,
)
from core.fitting.density import fit_map
from core.fitting.domains import DOMAINS
from core.fitting.map_quality import MapQuality, map_quality
from core.fitting.map_target import (
    RESOLUTION,
    MapTarget,
    file_resolution,
    heavy_atoms,
    occupancies,
)
from core.fitting.morph import morph_frames
from core.fitting.settle import FitResult
from core.geometry.validation import validate
from core.protein.model import EditableModel
from core.protein.structure import Structure, ca_rows
from core.protein.writing import write_models
from core.surfaces.map_file import MAP_SUFFIXES, read_map
from core.surfaces.volume import MapError

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
    parser.add_argument("--to", required=True, type=Path, metavar="TARGET",
                        help="the structure to move it onto (PDB or mmCIF), or a density map to move it into "
                             "(CCP4/MRC/MAP, optionally gzipped, or the 2mFo-DFc map of an MTZ file)")
    parser.add_argument("--chain", metavar="ID", help="chain of MODEL to fit (default: its first protein chain)")
    parser.add_argument("--target-chain", metavar="ID", help="chain of TARGET (default: its first protein chain)")
    _common_arguments(parser)
    parser.add_argument("--resolution", type=bounded(float, *RESOLUTION), metavar="Å",
                        help="for a map target: its resolution, which the model's density is simulated at "
                             f"({RESOLUTION[0]:g} to {RESOLUTION[1]:g} Å; default: the file's, where it gives one: "
                             "an MTZ's high-resolution limit, a map's header label)")
    parser.add_argument("--no-domains", dest="domains", action="store_false",
                        help="for a map target: leave out the first stage, the chain's smaller dynamic domain moved "
                             "as a rigid body before the levels (it runs when the levels start at 0)")
    parser.add_argument("--no-regularize", dest="regularize", action="store_false",
                        help="leave the residues as the fit remaps them (peptide junctions may stretch)")
    parser.add_argument("-o", "--output", required=True, type=Path, metavar="OUT",
                        help="output file; PDB or mmCIF by the extension (.pdb, .cif, optionally .gz)")
    parser.add_argument("--json", action="store_true", help="print a JSON object instead of text")


def run_fit(args: argparse.Namespace) -> int:
    checked_output(args.output, args.overwrite)
    structure = load(args.file, args.model)
    model = EditableModel(structure)
    before = validate(structure, model.coords).counts
    result, report, measure, score, judge = (_fit_map if _is_map(args.to) else _fit_structure)(model, args)
    after = validate(structure, model.coords).counts
    final = report["final"] = round(score(), 4)
    quality = judge() if judge is not None else None
    if quality is not None:
        labels = [label for segment in structure.segments for label in segment.labels]
        report["map_fit"] = {"cc_mask": round(quality.cc_mask, 4), "cc_box": round(quality.cc_box, 4),
                             "outside_density": [labels[k] for k in quality.outside]}
    try:
        written = model.save(args.output, overwrite=args.overwrite)
    except FileExistsError as error:
        raise InputError(f"{error} (pass --overwrite to replace it)") from None
    except (ValueError, OSError) as error:
        raise InputError(str(error)) from None
    what = report.pop("what")
    levels = [{"level": f.level if f.level != DOMAINS else "domains", "control_points": f.control_points,
               measure: round(f.score, 4), "seconds": round(f.seconds, 4)} for f in result.levels]
    for level, f in zip(levels, result.levels):
        if f.resolution is not None:  # a map, as that level saw it
            level["resolution"] = round(f.resolution, 2)
        if f.level == DOMAINS:
            level["moved"] = f.motion
    report.update({
        "model": str(args.file), "target": str(args.to), "levels": levels,
        "dropped_levels": result.dropped, "regularized": args.regularize, "refined": bool(result.refinement),
        "validation": {kind: {"before": before[kind], "after": after[kind]} for kind, _ in CHECKED},
        "output": str(written),
    })
    if args.json:
        print(json.dumps(report, indent=2))
        return 0
    name, unit = ("Cα rmsd", " Å") if measure == "rmsd" else ("correlation", "")
    print(f"{what}; {name} after each level:")
    for f, level in zip(result.levels, levels):
        seen = f" at {level['resolution']:4.1f} Å" if "resolution" in level else ""
        if f.level == DOMAINS:
            print(f"  domains: {f.motion or 'none moved (no gain in correlation)'}; {name} {f.score:6.3f}{unit}{seen}, "
                  f"{f.seconds:6.2f} s")
            continue
        print(f"  level {f.level}: {f.control_points:4d} control points, {name} {f.score:6.3f}{unit}{seen}, "
              f"{f.seconds:6.2f} s")
    if result.dropped:
        print(f"  levels {', '.join(map(str, result.dropped))} undone: the regularized model kept clearly more bad "
              "peptide junctions and Ramachandran outliers than the input (the target's backbone differs at that detail)")
    if result.refinement:
        print("  refined: every residue moved into the map on its own, its side chains turning, and regularized")
    done = "regularized" if args.regularize else "not regularized"
    changes = ", ".join(f"{before[k]} -> {after[k]} {label}" for k, label in CHECKED)
    print(f"{done}: {name} {final:.3f}{unit}; {changes}")
    if quality is not None:
        print(f"the map's judgement: {quality.summary(labels)}")
    print(f"wrote {written}")
    return 0


def _is_map(path: Path) -> bool:
    name = path.name.lower().removesuffix(".gz")
    return name.endswith(MAP_SUFFIXES)


Fitted = tuple[FitResult, dict, str, Callable[[], float], Callable[[], MapQuality] | None]
"""A settled fit, the report so far, the name of its score, the score of the model now, and
for a map how well the model fits it now."""


def _fit_structure(model: EditableModel, args: argparse.Namespace) -> Fitted:
    if args.resolution is not None or not args.domains:
        raise InputError("--resolution and --no-domains are for a map target; TARGET is a structure")
    target = load(args.to)
    pairs, pairing, rows = _paired(model, args.chain, target, args.target_chain, args.pairing)
    result = _settled(lambda levels: fit_conformation(model, pairs, levels, regularize=args.regularize), model,
                      args.levels)
    report = {"pairing": pairing, "pairs": len(rows), "what": f"{len(rows)} residue pairs ({pairing})"}
    return result, report, "rmsd", lambda: superpose(model.coords[rows], np.concatenate([p.target for p in pairs])).rmsd, \
        None


def _fit_map(model: EditableModel, args: argparse.Namespace) -> Fitted:
    if args.target_chain is not None or args.pairing != "auto":
        raise InputError("--target-chain and --pairing are for a structure target; TARGET is a map")
    structure = model.structure
    segments = chain_segments(structure, structure.segments[0].chain if args.chain is None else args.chain) \
        if structure.segments else []
    if not segments:
        raise InputError(f"{structure.path}: no protein chain to fit")
    try:
        density = read_map(args.to)
    except MapError as error:
        raise InputError(str(error)) from None
    given = (args.resolution, "--resolution") if args.resolution is not None else file_resolution(density)
    if given is None:
        raise InputError(f"{args.to}: the file does not give its resolution; pass --resolution (Å), the resolution "
                         "to simulate the model's density at")
    resolution, source = given
    try:
        target = MapTarget(density, resolution, model.coords[heavy_atoms(model)])
    except (MapError, ValueError) as error:
        raise InputError(str(error)) from None
    first = [DOMAINS] if args.domains and args.levels[0] == 0 else []
    result = _settled(lambda levels: fit_map(model, segments, target, [*first, *levels], regularize=args.regularize),
                      model, args.levels)
    rows = heavy_atoms(model)
    report = {"resolution": round(resolution, 2), "resolution_from": source, "segments": len(segments),
              "what": f"{len(segments)} segment(s) into the map at {resolution:.3g} Å ({source}; each level into the "
                      "map blurred as that level sees it)"}
    judged = rows[structure.atom_residue[rows] >= 0]  # the atoms of the chains' residues
    return result, report, "cc", lambda: target.correlation(model.coords[rows], occupancies(model, rows)), \
        lambda: map_quality(target, model.coords[judged], structure.atom_residue[judged], structure.n_residues,
                            occupancies(model, judged))


def _settled(fit: Callable[[range], FitResult], model: EditableModel, bounds: tuple[int, int]) -> FitResult:
    """``fit`` over the levels ``bounds`` (refused past the finest level of ``model``'s longest segment)."""
    finest = max((ribbon.level for ribbon in model.ribbons), default=0)
    if bounds[1] > finest:
        raise InputError(f"--levels {bounds[0]}-{bounds[1]}: the finest level of {model.structure.path.name} is "
                         f"{finest} (its longest segment at full resolution); give levels up to {finest}")
    try:
        return fit(range(bounds[0], bounds[1] + 1))
    except ValueError as error:
        raise InputError(str(error)) from None


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
    checked_output(args.output, args.overwrite)
    start = load(args.file_a)
    model = EditableModel(start)
    pairs, pairing, _ = _paired(model, chain_a, load(args.file_b), chain_b, args.pairing)
    fits = _settled(lambda levels: fit_conformation(model, pairs, levels, regularize=False), model, args.levels).levels
    with tqdm(total=args.frames, unit="frame", desc="morphing", file=sys.stderr, mininterval=0.5) as progress:
        frames = morph_frames(EditableModel(start), fits, args.frames, done=progress.update)
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
    model: EditableModel, chain: str | None, target: Structure, target_chain: str | None, pairing: str
) -> tuple[list[Pairs], str, np.ndarray]:
    """The residues of the model's chain paired with the target chain's, the pairing used
    and the Cα rows of the paired residues."""
    structure = model.structure
    if not structure.segments or not target.segments:
        missing = structure if not structure.segments else target
        raise InputError(f"{missing.path}: no protein chain to fit")
    numbers = chain_segments(structure, structure.segments[0].chain if chain is None else chain)
    target_numbers = chain_segments(target, target.segments[0].chain if target_chain is None else target_chain)
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
    return pairs, used, rows
