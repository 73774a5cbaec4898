"""Nucleic acids drawn by default (#34): a tube through each strand's phosphates and a slab
per base coloured by base, for a DNA duplex only viewed and beside an edited protein."""

from collections.abc import Callable
from pathlib import Path

import numpy as np
from PySide6.QtCore import Qt
from pytestqt.qtbot import QtBot

from app.editor.docks.sequence import STRAND_GAP, _light
from app.editor.interaction.identify import Hit, describe
from app.editor.main_window import MainWindow
from app.editor.scene import nucleic
from app.editor.scene.layers.base import Layer
from app.editor.scene.layers.chains import Others
from app.editor.scene.layers.nucleic import NucleicLayer
from core.protein.reading import read_structure
from core.protein.structure import nucleotide_letter

DATA = Path(__file__).resolve().parents[2] / "data"

Opener = Callable[[str], MainWindow]


def test_a_dna_duplex_is_drawn_as_tubes_through_its_phosphates_and_slabs_per_base(open_window: Opener) -> None:
    window = open_window("1BNA.pdb.gz")  # the Dickerson dodecamer: two strands, no protein
    scene, atoms = window.scene, window.document.structure.atoms
    assert not window.document.editable and scene.actors["nucleic_tube"].GetVisibility()
    found = scene.part(NucleicLayer).found
    assert len(found) == 24 and list(found.strand_start) == [0, 12, 24]
    rings = np.asarray(scene.meshes["nucleic_tube"].points).reshape(-1, nucleic.SIDES, 3).mean(axis=1)
    strand = rings[: 11 * nucleic.SAMPLES + 1]
    phosphates = atoms.coords[found.backbone[:12]]
    np.testing.assert_allclose(strand[:: nucleic.SAMPLES], phosphates, atol=1e-4)  # through every phosphorus
    letters = [str(name)[-1] for name in atoms.resname[found.backbone[:12]]]
    assert "".join(letters) == "CGCGAATTCGCG"
    colours = np.asarray(scene.meshes["nucleic_bases"].point_data["colours"])
    owner = scene.part(NucleicLayer)._base_owner
    for k, letter in enumerate(letters):
        assert tuple(colours[owner == k][0]) == nucleic.BASE_COLOURS[letter]
    outline = found.outline[found.outline_start[4]:found.outline_start[5]]  # A5: a purine's nine ring atoms
    assert len(outline) == 9
    bases = np.asarray(scene.meshes["nucleic_bases"].points)[owner == 4]
    np.testing.assert_allclose(bases[:9], atoms.coords[outline], atol=1e-4)
    window.display_panel.layer_boxes[Layer.NUCLEIC].setChecked(False)
    assert not scene.actors["nucleic_tube"].GetVisibility() and not scene.actors["nucleic_bases"].GetVisibility()


def test_a_strand_runs_on_through_its_modified_nucleotide() -> None:
    atoms = read_structure(DATA / "4OPJ.pdb.gz").atoms  # TCY, a modified nucleotide, sixth of each 12-mer
    found = nucleic.nucleotides(atoms)
    assert list(found.strand_start) == [0, 12, 24]  # not broken in two at it
    assert "TCY" in set(atoms.resname[found.backbone].tolist())
    sixth = [int(found.backbone[start + 5]) for start in found.strand_start[:-1]]
    assert [str(atoms.resname[row]) for row in sixth] == ["TCY", "TCY"]
    adenine = nucleic.BASE_COLOURS["A"]  # the file's MODRES records say TCY is a modified dA
    assert [tuple(found.colours[start + 5]) for start in found.strand_start[:-1]] == [adenine] * 2


def test_a_modified_nucleotide_is_lettered_and_coloured_as_its_parent() -> None:
    letters = {name: nucleotide_letter(name) for name in ("DA", "DT", "G", "U", "PSU", "5CM", "OMG", "TCY")}
    assert letters == {"DA": "A", "DT": "T", "G": "G", "U": "U", "PSU": "u", "5CM": "c", "OMG": "g", "TCY": "N"}
    parents = {"TCY": "DA", "PSU": "DC"}  # a file's own records: gemmi's table comes first where it knows
    assert [nucleotide_letter(name, parents) for name in ("TCY", "PSU", "DG", "XYZ")] == ["a", "u", "G", "N"]


def test_dna_beside_an_edited_protein_stays_where_it_is_and_hides_with_the_other_chains(open_window: Opener) -> None:
    window = open_window("1LCD.cif.gz")  # the lac repressor headpiece on its operator
    scene, document = window.scene, window.document
    assert document.editable and len(scene.part(NucleicLayer).found) > 20
    tube = np.array(scene.meshes["nucleic_tube"].points)
    shown = scene.shown_control_points()
    window.rw.move(int(shown[len(shown) // 2]), (2.0, 1.0, 0.0))
    assert np.array_equal(np.array(scene.meshes["nucleic_tube"].points), tube)
    scene.set_others(Others.HIDDEN)  # the DNA's chains are not the edited one
    hidden = np.array(scene.meshes["nucleic_tube"].points)
    assert np.ptp(hidden, axis=0).max() == 0.0
    scene.set_others(Others.SHOWN)
    np.testing.assert_array_equal(np.array(scene.meshes["nucleic_tube"].points), tube)


def test_the_sequence_bar_shows_the_strands_letters_on_their_bases_colours(open_window: Opener) -> None:
    window = open_window("1BNA.pdb.gz")
    strip = window.sequence_bar.strip
    assert [(chain, letters) for chain, letters, _ in strip._strands] == [("A", "CGCGAATTCGCG"), ("B", "CGCGAATTCGCG")]
    image = strip.grab().toImage()
    cell = strip.cell_rect(STRAND_GAP)  # the first strand's first letter, a C
    colour = image.pixelColor(cell.left() + 2, cell.top() + 2)
    assert (colour.red(), colour.green(), colour.blue()) == _light(nucleic.BASE_COLOURS["C"])
    assert strip.sizeHint().width() >= (2 * (12 + STRAND_GAP)) * strip.cell


def test_the_sequence_bar_letters_a_modified_nucleotide_as_its_parent_within_its_strand(open_window: Opener) -> None:
    window = open_window("4OPJ.pdb.gz")  # TCY, which gemmi does not know, is a dA by the file's MODRES
    strands = [(chain, letters) for chain, letters, _ in window.sequence_bar.strip._strands]
    assert strands == [("B", "CGCGAaTTCGCG"), ("D", "CGCGAaTTCGCG")]


def test_hovering_a_nucleotide_says_it_is_not_edited(open_window: Opener) -> None:
    window = open_window("1LCD.cif.gz")
    atoms = window.document.structure.atoms
    row = int(np.flatnonzero((atoms.category == "nucleic") & (atoms.name == "P"))[0])
    text = describe(window.document, Hit("atom", atoms.coords[row], -1, row))
    assert text.endswith("P (P) · nucleic acid: drawn, not edited (no curve)")


def test_a_click_on_a_strands_letter_selects_its_nucleotide(open_window: Opener, qtbot: QtBot) -> None:
    """1BNA: B:DT20's letter (the eighth of strand B) clicked in the sequence bar selects that
    nucleotide, framed there, and centres the view on it; beside a protein's segment (1LCD),
    the strands' letters come after the segment's."""
    window = open_window("1BNA.pdb.gz")
    strip, atoms = window.sequence_bar.strip, window.document.structure.atoms
    cell = strip.cell_rect(2 * STRAND_GAP + 12 + 7)  # strand A's twelve letters, then B's eighth
    qtbot.mouseClick(strip, Qt.MouseButton.LeftButton, pos=cell.center())
    nucleotide = np.flatnonzero((atoms.chain == "B") & (atoms.resseq == 20))
    assert window.rw.selection == ["B:DT20"] and np.array_equal(window.document.selected_groups, nucleotide)
    np.testing.assert_allclose(window.plotter.camera.focal_point, atoms.coords[nucleotide].mean(axis=0), atol=1e-6)
    image = strip.grab().toImage()
    frame = image.pixelColor(cell.left(), cell.top() + cell.height() // 2)
    assert (frame.red(), frame.green(), frame.blue()) != _light(nucleic.BASE_COLOURS["T"])  # framed
    qtbot.mouseClick(strip, Qt.MouseButton.LeftButton, pos=strip.cell_rect(STRAND_GAP - 1).center())  # a gap
    assert window.rw.selection == ["B:DT20"]

    window = open_window("1LCD.cif.gz")  # the lac repressor's headpiece (51 residues) on its operator
    strip = window.sequence_bar.strip
    qtbot.mouseClick(strip, Qt.MouseButton.LeftButton, pos=strip.cell_rect(51 + STRAND_GAP).center())
    assert window.rw.selection == ["B:DA1"]
