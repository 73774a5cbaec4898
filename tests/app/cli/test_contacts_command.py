"""``ribbonwave contacts`` on real entries, through ``main``: a ligand's hydrogen bonds, a zinc
site's bonds (the file's own LINK records), a base pair, and bad input."""

import json
from pathlib import Path

import gemmi
from test_validate_command import run

DATA = Path(__file__).resolve().parents[2] / "data"


def test_a_ligands_hydrogen_bonds_as_text(capsys):
    status, out, _ = run(capsys, "contacts", DATA / "3PTB.pdb.gz", "resn BEN")
    assert status == 0
    lines = out.splitlines()
    assert lines[0] == f"{DATA / '3PTB.pdb.gz'}: 3PTB, A:BEN1"
    assert lines[1].startswith("  6 hydrogen bonds")
    assert lines[2].split() == ["A:ASP189", "OD1", "A:BEN1", "N1", "2.92", "Å"]
    assert lines[-1].startswith("  0 metal bonds")


def test_a_zinc_sites_bonds_are_the_files_links_in_json(capsys):
    status, out, _ = run(capsys, "contacts", DATA / "1AYE.pdb.gz", "A:ZN400", "--json")
    assert status == 0
    data = json.loads(out)
    assert data["selection"] == ["A:ZN400"] and data["model"] == 1 and data["hydrogen_bonds"] == []
    st = gemmi.read_structure(str(DATA / "1AYE.pdb.gz"))
    links = {(round(c.reported_distance, 2), frozenset(f"{p.chain_name}:{p.res_id.name}{p.res_id.seqid.num} {p.atom_name}"
                                                        for p in (c.partner1, c.partner2)))
             for c in st.connections if c.type == gemmi.ConnectionType.MetalC}
    assert {(round(b["distance"], 2), frozenset(b["atoms"])) for b in data["metal_bonds"]} == links


def test_a_nucleotides_base_pair(capsys):
    status, out, _ = run(capsys, "contacts", DATA / "1BNA.pdb.gz", "B:20", "--json")  # DNA only
    pairs = {tuple(b["atoms"]) for b in json.loads(out)["hydrogen_bonds"]}
    assert status == 0 and {("A:DA5 N6", "B:DT20 O4"), ("A:DA5 N1", "B:DT20 N3")} <= pairs


def test_bad_input_gives_a_message(capsys, tmp_path):
    for argv, message in [((DATA / "3PTB.pdb.gz", "resn XYZ"), "no residue XYZ"),
                          ((DATA / "3PTB.pdb.gz", "(chain A"), "expected a closing parenthesis"),
                          ((tmp_path / "none.pdb", "A:1"), "no such file")]:
        status, out, err = run(capsys, "contacts", *argv)
        assert status == 1 and out == "" and err.startswith("ribbonwave: error:") and message in err
        assert "Traceback" not in err
