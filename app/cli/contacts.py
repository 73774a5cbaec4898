"""The headless ``contacts`` command: the hydrogen bonds and metal bonds of a selection, as the
editor's *Show Polar Contacts of Selection* measures them (:mod:`core.geometry.contacts`).

``contacts --json`` is a contract for other programs: ``file``, ``model``, ``selection`` (the
labels selected), and ``hydrogen_bonds`` and ``metal_bonds``, each a list of ``atoms`` (two
atom labels) and ``distance`` (Å).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from app.cli.structure import load, model_argument
from app.errors import InputError
from core.geometry.contacts import CLOSEST, METAL_REACH, POLAR_REACH, selection_contacts
from core.geometry.topology import topology
from core.protein.lookup import find_selection


def contacts_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", type=Path, metavar="FILE", help="structure file (PDB or mmCIF, optionally gzipped)")
    parser.add_argument("selection", metavar="SELECTION",
                        help="what to find the contacts of, as Go to Residue reads it: 'resn BEN', 'A:HEM', "
                             "'chain A', 'A:189', 'resn ZN', 'byres organic around 4'")
    model_argument(parser)
    parser.add_argument("--json", action="store_true", help="print a JSON object instead of text")


def run_contacts(args: argparse.Namespace) -> int:
    structure = load(args.file, args.model, require_protein=False)
    try:
        selected = find_selection(structure, args.selection)
    except ValueError as error:
        raise InputError(str(error)) from None
    polar, metal = selection_contacts(structure, structure.coords, selected)
    label = topology(structure).atom_label
    listed = {kind: [([label(int(a)), label(int(b))], float(np.linalg.norm(structure.coords[a] - structure.coords[b])))
                     for a, b in pairs] for kind, pairs in (("hydrogen_bonds", polar), ("metal_bonds", metal))}
    labels = selected.labels(structure)
    if args.json:
        found = {kind: [{"atoms": atoms, "distance": round(distance, 3)} for atoms, distance in items]
                 for kind, items in listed.items()}
        print(json.dumps({"file": str(structure.path), "model": structure.model_number, "selection": labels}
                         | found, indent=2, ensure_ascii=False))
        return 0
    named = ", ".join(labels[:4]) + (f" … {labels[-1]} ({len(labels)} selected)" if len(labels) > 4 else "")
    print(f"{structure.path}: {structure.entry_id}, {named}")
    titles = {"hydrogen_bonds": f"hydrogen bonds (a donor and an acceptor, N or O, {CLOSEST:g}-{POLAR_REACH:g} Å)",
              "metal_bonds": f"metal bonds (N, O or S within {METAL_REACH:g} Å of a metal)"}
    for kind, found in listed.items():
        print(f"  {len(found)} {titles[kind]}")
        for (first, second), distance in found:
            print(f"    {first:<20} {second:<20} {distance:.2f} Å")
    return 0
