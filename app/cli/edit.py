"""The headless ``edit`` command: one multiresolution edit of a structure, saved as a new file."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from app.arguments import LEVEL, bounded
from app.cli.curve import ribbon_argument
from app.cli.structure import chain_segments, checked_output, load, model_argument
from app.errors import InputError
from core.geometry.regularize import regularized
from core.geometry.validation import validate
from core.protein.model import EditableModel
from core.protein.ribbon import RibbonKind
from core.protein.structure import BackboneSegment


def edit_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", type=Path, metavar="FILE", help="structure file (PDB or mmCIF, optionally gzipped)")
    model_argument(parser)
    parser.add_argument("--chain", required=True, metavar="ID", help="chain to edit")
    parser.add_argument("--segment", type=bounded(int, 0, 100_000), default=0, metavar="S",
                        help="segment of the chain (0-based, chains split at gaps; default 0)")
    parser.add_argument("--level", type=bounded(float, *LEVEL), required=True, metavar="L", help="Carson level of the edit")
    target = parser.add_mutually_exclusive_group(required=True)
    target.add_argument("--point", type=bounded(int, 0, 10_000_000), metavar="K",
                        help="control point to move (0-based, among those of the curve shown at L)")
    target.add_argument("--residue", metavar="RESSEQ[ICODE]", help="move the curve point of this residue instead")
    parser.add_argument("--move", required=True, type=_vector, metavar="DX,DY,DZ", help="displacement in Å")
    ribbon_argument(parser)
    parser.add_argument("-o", "--output", required=True, type=Path, metavar="OUT",
                        help="output file; PDB or mmCIF by the extension (.pdb, .cif, optionally .gz)")
    parser.add_argument("--overwrite", action="store_true", help="replace OUT if it exists (even the input file)")
    parser.add_argument("--regularize", action="store_true",
                        help="then move the residues again (rigid, turning carbonyls and clashing side chains) "
                             "to ideal peptide junctions without new clashes or Ramachandran outliers")


def run_edit(args: argparse.Namespace) -> int:
    checked_output(args.output, args.overwrite)
    structure = load(args.file, args.model)
    number = chain_segments(structure, args.chain, args.segment)[0]
    model = EditableModel(structure, RibbonKind(args.ribbon))
    ribbon = model.ribbons[number]
    try:
        if args.point is not None:
            edit = model.move_point(number, args.level, args.point, args.move)
        else:
            residue = _residue_index(structure.segments[number], args.residue)
            edit = model.tug(number, args.level, float(ribbon.residue_u[residue]), args.move)
        if args.regularize:
            plain, edit = edit, regularized(model, edit)
        model.apply(edit)
        written = model.save(args.output, overwrite=args.overwrite)
    except FileExistsError as error:
        raise InputError(f"{error} (pass --overwrite to replace it)") from None
    except (ValueError, OSError) as error:
        raise InputError(str(error)) from None
    labels = structure.segments[number].labels
    moved = f"{labels[edit.residues[0]]}-{labels[edit.residues[-1]]}" if len(edit.residues) else "none"
    of_model = f" of model {structure.model_number}" if structure.n_models > 1 else ""
    print(f"moved {len(edit.residues)} residues ({moved}), {len(edit.rows)} atoms{of_model}; "
          f"wrote {written}")
    if args.regularize:
        region = structure.segments[number].residue_index[edit.residues]
        before = np.array(structure.coords)
        before[plain.rows] = plain.new_coords  # the edit without regularization
        flagged = [validate(structure, coords, residues=region).counts for coords in (before, model.coords)]
        print("regularized: " + ", ".join(
            f"{flagged[0][kind]} -> {flagged[1][kind]} {name}" for kind, name in
            (("peptide_bond", "bad peptide bonds"), ("ca_ca", "bad Cα–Cα"), ("clash", "clashes"),
             ("ramachandran", "Ramachandran outliers"))))
    return 0


def _vector(text: str) -> np.ndarray:
    parts = text.split(",")
    try:
        vector = np.array([float(p) for p in parts])
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected three numbers DX,DY,DZ; got {text!r}") from None
    if len(vector) != 3 or not np.all(np.isfinite(vector)):
        raise argparse.ArgumentTypeError(f"expected three finite numbers DX,DY,DZ; got {text!r}")
    return vector


def _residue_index(segment: BackboneSegment, label: str) -> int:
    """Index in ``segment`` of the residue numbered ``label`` (e.g. '52' or '52A')."""
    for i, (number, icode) in enumerate(zip(segment.resseq.tolist(), segment.icode)):
        if f"{number}{icode}" == label.strip():
            return i
    raise InputError(f"no residue {label} in chain {segment.chain} segment {segment.labels[0]}-{segment.labels[-1]}")
