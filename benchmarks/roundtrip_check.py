"""Round trip of unedited structures: what ``edit --move 0,0,0`` writes reads back as the input.

Usage: ``python benchmarks/roundtrip_check.py FOLDER [...]`` (PDB and mmCIF files, searched
recursively). Each file is written as PDB (when PDB can hold it) and as mmCIF without a
move, and read back; the script compares, record by record, the atoms of every model
(names, residues, chains, altlocs, coordinates, occupancies, B-factors, elements), the
MTRIX, ORIGX, SCALE, LINK, SSBOND, CISPEP and HET records of PDB input, and every mmCIF
category of mmCIF input (which is written byte for byte). It prints one line per file with
a difference, and a count per kind of record.
"""

from __future__ import annotations

import gzip
import sys
import tempfile
from collections import Counter
from pathlib import Path

import gemmi

from core.protein.input_files import StructureError
from core.protein.reading import read_structure
from core.protein.writing import write_structure

SUFFIXES = (".pdb", ".ent", ".cif", ".mmcif")
PDB_RECORDS = ("MTRIX1", "MTRIX2", "MTRIX3", "ORIGX1", "ORIGX2", "ORIGX3", "SCALE1", "SCALE2", "SCALE3",
               "LINK", "SSBOND", "CISPEP", "HET")


def atoms(path: Path) -> list[tuple]:
    """Every atom of every model, as comparable fields."""
    st = gemmi.read_structure(str(path))
    return [(model.num, chain.name, str(res.seqid), res.name, atom.name, atom.altloc, atom.element.name,
             round(atom.pos.x, 3), round(atom.pos.y, 3), round(atom.pos.z, 3), round(atom.occ, 2),
             round(atom.b_iso, 2))
            for model in st for chain in model for res in chain for atom in res]


def records(text: str, name: str) -> list[str]:
    return [line.rstrip() for line in text.splitlines() if line[:6].strip() == name]


def text_of(path: Path) -> str:
    data = path.read_bytes()
    return (gzip.decompress(data) if data[:2] == b"\x1f\x8b" else data).decode("latin-1")


def check(path: Path, folder: Path) -> list[str]:
    """The kinds of record that did not come back (empty: all did)."""
    structure = read_structure(path)
    original = text_of(path)
    source_atoms = atoms(path)
    problems = []
    cif = write_structure(structure, structure.coords, folder / "out.cif", overwrite=True)
    if atoms(cif) != source_atoms:
        problems.append("mmCIF atoms")
    if structure.source_format == "mmcif":
        if cif.read_text(encoding="latin-1") != original:
            problems.append("mmCIF bytes")
        return problems
    try:
        pdb = write_structure(structure, structure.coords, folder / "out.pdb", overwrite=True)
    except StructureError:  # PDB cannot hold it (long chain ids, big coordinates): refused, as it should be
        return problems
    if atoms(pdb) != source_atoms:
        problems.append("PDB atoms")
    written = pdb.read_text(encoding="latin-1")
    problems += [name for name in PDB_RECORDS if records(written, name) != records(original, name)]
    return problems


def main() -> None:
    paths = sorted(p for folder in map(Path, sys.argv[1:]) for p in folder.rglob("*")
                   if p.name.lower().removesuffix(".gz").endswith(SUFFIXES))
    counts: Counter[str] = Counter()
    checked = unreadable = 0
    with tempfile.TemporaryDirectory() as tmp:
        for path in paths:
            try:
                problems = check(path, Path(tmp))
            except StructureError as error:  # e.g. DNA only: nothing to edit
                unreadable += 1
                print(f"{path.name}: not read ({error})")
                continue
            checked += 1
            counts.update(problems)
            if problems:
                print(f"{path.name}: differs in {', '.join(problems)}")
    print(f"{checked} files written and read back, {unreadable} not read; "
          f"{sum(1 for _ in counts.elements())} differences: {dict(counts) or 'none'}")


if __name__ == "__main__":
    main()
