"""The headless ``validate`` command: the geometry report of :mod:`core.geometry.validation`.

``validate --json`` is a contract for other programs: the fields of
:meth:`core.geometry.validation.ValidationReport.to_dict` plus ``file`` and ``model``.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from app.cli.structure import load, model_argument
from app.errors import InputError
from core.geometry.validation import KINDS, validate

TITLES = {
    "peptide_bond": "peptide bonds C–N outside ideal ± 0.05 Å",
    "ca_ca": "Cα–Cα distances outside 3.80 ± 0.1 Å (cis 2.94 ± 0.25 Å)",
    "angle_ca_c_n": "angles Cα–C–N beyond 4σ",
    "angle_c_n_ca": "angles C–N–Cα beyond 4σ",
    "omega": "non-planar peptides (ω beyond 30°)",
    "ramachandran": "Ramachandran outliers",
    "clash": "heavy-atom clashes (overlap > 0.4 Å)",
}


def validate_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", type=Path, metavar="FILE", help="structure file (PDB or mmCIF, optionally gzipped)")
    model_argument(parser)
    parser.add_argument("--json", action="store_true", help="print a JSON object instead of text")
    parser.add_argument("--worst", type=int, default=10, metavar="N",
                        help="list the N most severe problems (default 10; all with --json if N < 0)")


def run_validate(args: argparse.Namespace) -> int:
    structure = load(args.file, args.model)
    report = validate(structure)
    if args.json:
        data = {"file": str(structure.path), "model": structure.model_number} | report.to_dict(None if args.worst < 0 else args.worst)
        print(json.dumps(data, indent=2, ensure_ascii=False))
        return 0
    if args.worst < 0:
        raise InputError(f"--worst must be >= 0 for text output; got {args.worst}")
    counts, checked = report.counts, report.checked
    of_model = f" model {structure.model_number} of {structure.n_models}" if structure.n_models > 1 else ""
    print(f"{structure.path}: {structure.entry_id}{of_model}, {checked['ca_ca']} junctions, "
          f"{checked['ramachandran']} residues with φ/ψ, {checked['clash']} heavy atoms")
    print(f"  {'flagged':>7} {'checked':>8}")
    for kind in KINDS:
        per = 1000.0 if kind == "clash" else 100.0
        share = f"{per * counts[kind] / max(checked[kind], 1):.1f}{' per 1000 atoms' if kind == 'clash' else '%'}"
        print(f"  {counts[kind]:>7} {checked[kind]:>8}  {TITLES[kind]} ({share})")
    print(f"  {len(report.cis):>7} {'':>8}  cis peptides (measured against cis ideals)")
    worst = report.worst(args.worst)
    if worst:
        print(f"worst {len(worst)}:")
        for flag in worst:
            print(f"  {flag.severity:>6.2f}  {flag.kind:<13} {flag.where:<32} {flag.detail}")
    return 0
