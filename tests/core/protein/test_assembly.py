"""Biological assemblies built from a file's assembly records, as gemmi builds them."""

from __future__ import annotations

import gzip
from pathlib import Path

import gemmi
import numpy as np
import pytest

from core.protein.assembly import assemblies, assembly_path, assembly_text
from core.protein.input_files import StructureError
from core.protein.reading import read_structure

DATA = Path(__file__).resolve().parents[2] / "data"


def test_an_assembly_is_every_copy_its_operators_make() -> None:
    """3JQH's 24-mer: copy k of chain A is the asymmetric unit moved by operator k, keeps
    its residues and its helix (from the file's records, not computed again)."""
    path = DATA / "3JQH.cif.gz"
    unit = read_structure(path)
    assert [a.describe() for a in assemblies(path)] == ["assembly 1: 24 chains, 5,712 atoms"]
    built = read_structure(assembly_path(path, 1), assembly_text(path, number=1).encode())
    assert built.n_atoms == 24 * unit.n_atoms and built.entry_id == "3JQH"
    assert [s.chain for s in built.segments] == [f"A{k}" for k in range(1, 25)]
    assert built.ss_source == unit.ss_source
    operators = gemmi.read_structure(str(path)).assemblies[0].generators[0].operators
    for k, (segment, operator) in enumerate(zip(built.segments, operators, strict=True)):
        assert segment.sequence == unit.segments[0].sequence and list(segment.ss) == list(unit.segments[0].ss)
        matrix = np.array(operator.transform.mat.tolist())
        expected = unit.coords @ matrix.T + np.array(operator.transform.vec.tolist())
        assert np.allclose(built.coords[k * unit.n_atoms:(k + 1) * unit.n_atoms], expected, atol=1e-3), k


def test_the_assembly_of_a_pdb_file_and_its_name() -> None:
    """REMARK 350 of a PDB file: 2HPR's second assembly is a dimer of its chain A."""
    path = DATA / "2HPR_A.pdb.gz"
    assert [a.chains for a in assemblies(path)] == [1, 2]
    text = assembly_text(path, gzip.decompress(path.read_bytes()), number=2)
    built = read_structure("x.cif", text.encode())
    unit = read_structure(path)
    assert [s.chain for s in built.segments] == ["A1"] * len(unit.segments) + ["A2"] * len(unit.segments)
    assert built.n_atoms == 2 * unit.n_atoms and built.source_format == "mmcif"
    assert assembly_path(path, 2) == DATA / "2HPR_A-assembly2.cif"


@pytest.mark.parametrize("number", [0, 2, True])
def test_an_assembly_the_file_does_not_have_is_refused(number: object) -> None:
    with pytest.raises(StructureError, match=r"3JQH.cif.gz: no assembly .*; the file has assemblies 1 to 1"):
        assembly_text(DATA / "3JQH.cif.gz", number=number)  # type: ignore[arg-type]


def test_a_file_without_assembly_records(tmp_path: Path) -> None:
    lines = gzip.decompress((DATA / "2HPR_A.pdb.gz").read_bytes()).decode().splitlines(keepends=True)
    bare = tmp_path / "bare.pdb"
    bare.write_text("".join(line for line in lines if not line.startswith("REMARK 350")))
    assert assemblies(bare) == []
    with pytest.raises(StructureError, match="bare.pdb: no assembly 1; the file has no assembly records"):
        assembly_text(bare, number=1)
