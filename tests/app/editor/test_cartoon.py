"""The cartoon (#34): flat ribbons in the peptide planes, arrows at strand ends, loops as tubes,
the edited segment's at the slider's level; rewritten in place by an edit, exactly undone."""

from pathlib import Path

import numpy as np
import pytest
from pytestqt.qtbot import QtBot

from app.editor.document import Document
from app.editor.main_window import MainWindow
from app.editor.scene import cartoon, curves
from app.editor.scene.layers.base import Layer
from app.editor.scene.layers.cartoon import CartoonLayer
from core.geometry.topology import topology

DATA = Path(__file__).resolve().parents[2] / "data"
VERTEX_TOLERANCE = 2e-5
"""Å: the meshes hold their vertices in single precision, as the renderer takes them."""


def _window(qtbot: QtBot, name: str) -> MainWindow:
    document = Document()
    document.open(DATA / name)
    window = MainWindow(document)
    qtbot.addWidget(window)
    window.show()
    qtbot.waitExposed(window)
    return window


def _rings(window: MainWindow, segment: int) -> np.ndarray:
    """(n_rings, sides, 3) the cartoon's ring vertices of ``segment`` (a copy)."""
    layer = window.scene.part(CartoonLayer)
    first, last, sides = layer.ring_start[segment], layer.ring_start[segment + 1], layer.sides
    return np.array(window.scene.meshes["cartoon"].points[first * sides:last * sides]).reshape(-1, sides, 3)


def _centres(window: MainWindow, segment: int) -> tuple[np.ndarray, np.ndarray]:
    document = window.document
    return document.paths[segment].centres(document.model.ribbons[segment].points)


def test_the_cartoon_is_shown_and_the_tube_is_a_choice(qtbot: QtBot) -> None:
    window = _window(qtbot, "1UBQ.pdb.gz")
    assert window.scene.actors["cartoon"].GetVisibility()
    assert "tube" not in window.scene.meshes  # hidden: not built (no memory) until first shown
    boxes = window.display_panel.layer_boxes
    boxes[Layer.TUBE].setChecked(True)
    boxes[Layer.CARTOON].setChecked(False)
    assert window.scene.actors["tube"].GetVisibility() and not window.scene.actors["cartoon"].GetVisibility()


@pytest.mark.parametrize("large", [False, True])
def test_the_ribbon_lies_in_the_peptide_planes_and_strands_end_in_arrows(qtbot: QtBot, large: bool,
                                                                         monkeypatch: pytest.MonkeyPatch) -> None:
    """At full resolution each helix or strand residue's middle ring lies across along its
    carbonyl C→O (made perpendicular to the curve), a ribbon as wide as its kind; on a strand's
    last residue the ribbon narrows from the arrow's base towards the C terminus. So too with
    the fewer rings, of fewer vertices, of a large structure (taken as one here)."""
    if large:
        monkeypatch.setattr(curves, "LARGE_RESIDUES", 50)
    window = _window(qtbot, "1UBQ.pdb.gz")
    document = window.document
    assert (document.paths[0].rings_per_residue, document.paths[0].sides) == ((4, 8) if large else (6, 12))
    document.set_level(document.max_level)
    segment = document.structure.segments[0]
    rings, (centres, tangents) = _rings(window, 0), _centres(window, 0)
    k = document.paths[0].rings_per_residue
    backbone = topology(document.structure).backbone[segment.residue_index]
    carbonyl = document.model.coords[backbone[:, 3]] - document.model.coords[backbone[:, 2]]
    strand_ends = 0
    ss = segment.ss
    inner = np.flatnonzero(np.isin(ss, ("H", "E")) & (np.roll(ss, 1) == ss) & (np.roll(ss, -1) == ss))
    for residue in inner[1:-1]:
        middle = residue * k + k // 2
        across = rings[middle, 0] - centres[middle]  # the vertex at angle 0: half-width a along the guide
        guide = carbonyl[residue] - carbonyl[residue] @ tangents[middle] * tangents[middle]
        cosine = abs(across @ guide) / np.linalg.norm(across) / np.linalg.norm(guide)
        assert cosine > np.cos(np.radians(1.0)), segment.labels[residue]
        through = np.linalg.norm(rings[middle, rings.shape[1] // 4] - centres[middle])
        assert through < 0.5 * np.linalg.norm(across), segment.labels[residue]  # flat
    for residue in np.flatnonzero((ss == "E") & (np.append(ss[1:], "C") != "E")):
        strand_ends += 1
        arrow = slice(residue * k, residue * k + k + 1)
        widths = np.linalg.norm(rings[arrow, 0] - centres[arrow], axis=1)
        assert widths[0] == pytest.approx(cartoon.ARROW, abs=VERTEX_TOLERANCE) and widths[-1] == pytest.approx(cartoon.LOOP.a, abs=VERTEX_TOLERANCE)
        assert np.all(np.diff(widths) < 0)  # narrowing towards the C terminus ...
        assert (centres[arrow][-1] - centres[arrow][0]) @ tangents[residue * k] > 0  # ... which is ahead
    assert strand_ends == 5  # ubiquitin's five strands
    loop = np.flatnonzero(segment.ss == "C")[2] * k + k // 2
    radii = np.linalg.norm(rings[loop] - centres[loop], axis=1)
    np.testing.assert_allclose(radii, cartoon.LOOP.a, atol=VERTEX_TOLERANCE)  # a round tube


@pytest.mark.parametrize("level", ["max", 4.5])
def test_a_drag_sweeps_the_moved_residues_again_and_undo_restores_every_vertex(qtbot: QtBot, level: object) -> None:
    window = _window(qtbot, "1UBQ.pdb.gz")
    document = window.document
    document.set_regularization(on_release=False)
    document.set_level(document.max_level if level == "max" else level)
    before, coords = _rings(window, 0), document.model.coords.copy()
    shown = window.scene.shown_control_points()
    window.rw.move(int(shown[len(shown) // 2]), (1.5, -1.0, 0.5))
    moved = np.unique(document.structure.atom_residue[np.any(document.model.coords != coords, axis=1)])
    after = _rings(window, 0)
    k = document.paths[0].rings_per_residue
    changed = np.flatnonzero(np.any(after != before, axis=(1, 2)))
    if level == "max":
        assert len(moved) == 10
        assert set(changed // k) <= set(moved) | {moved.min() - 1, moved.max() + 1}  # (the guides are interpolated)
        assert len(changed) >= 0.8 * len(moved) * k
    curve = document.level_curve(0)
    centres, _ = document.paths[0].centres(curve.control_points, slice(None), curve.level)
    np.testing.assert_allclose(after.mean(axis=1), centres, atol=VERTEX_TOLERANCE)  # on the curve as it is now
    assert not np.allclose(after[changed].mean(axis=1), before[changed].mean(axis=1), atol=0.05)
    window.rw.undo()
    np.testing.assert_array_equal(_rings(window, 0), before)


def test_the_edited_segments_cartoon_follows_the_slider(qtbot: QtBot) -> None:
    """At a coarse level the edited segment's cartoon is that of the level curve, its helices
    turned to rods (their carbonyls lie along the smoothed curve); the other segments stay
    at full resolution, and the full level draws the full-resolution curve again."""
    window = _window(qtbot, "4HHB.pdb.gz")
    document = window.document
    document.set_level(document.max_level)
    full = [_rings(window, g) for g in range(4)]
    document.set_level(5.0)
    coarse = _rings(window, 0)
    assert all(np.array_equal(_rings(window, g), full[g]) for g in range(1, 4))
    curve = document.level_curve(0)
    centres, _ = document.paths[0].centres(curve.control_points, slice(None), curve.level)
    np.testing.assert_allclose(coarse.mean(axis=1), centres, atol=VERTEX_TOLERANCE)  # swept along the level curve
    helix = np.repeat(document.structure.segments[0].ss == "H", document.paths[0].rings_per_residue)
    helix = np.append(helix, False)

    def round_rings(rings: np.ndarray, centres: np.ndarray) -> np.ndarray:
        width = np.linalg.norm(rings[:, 0] - centres, axis=1)
        return np.linalg.norm(rings[:, rings.shape[1] // 4] - centres, axis=1) > 0.8 * width

    assert round_rings(coarse, centres)[helix].mean() > 0.5
    assert round_rings(full[0], _centres(window, 0)[0])[helix].mean() < 0.1
    document.set_level(document.max_level)
    np.testing.assert_allclose(_rings(window, 0), full[0], atol=1e-9)
    document.set_segment(2)  # another edited segment: the first back at full resolution
    document.set_level(4.0)
    np.testing.assert_allclose(_rings(window, 0), full[0], atol=1e-9)
    assert not np.allclose(_rings(window, 2), full[2])


def test_helices_as_cylinders_lie_on_their_axes(qtbot: QtBot) -> None:
    """The option draws each helix as a round cylinder of :data:`~app.editor.scene.cartoon.CYLINDER`'s
    radius whose rings lie on one line; the strands stay as they were, and switching back
    draws the spiral ribbons again."""
    window = _window(qtbot, "1AKE_adk_closed.pdb.gz")
    document = window.document
    document.set_level(document.max_level)
    spiral = _rings(window, 0)
    window.display_panel.cylinders.setChecked(True)
    rings = _rings(window, 0)
    k = document.paths[0].rings_per_residue
    ss = document.structure.segments[0].ss
    helices = cartoon.helices(ss, k)
    assert len(helices) >= 8  # adenylate kinase's helices
    for first, last in helices:
        centres = rings[first:last + 1].mean(axis=1)
        radii = np.linalg.norm(rings[first:last + 1] - centres[:, None, :], axis=2)
        np.testing.assert_allclose(radii, cartoon.CYLINDER.a, atol=VERTEX_TOLERANCE)
        spread = np.linalg.svd(centres - centres.mean(axis=0), compute_uv=False)
        assert spread[1] < 1e-6 * spread[0] + 1e-9  # on one line
    strands = np.flatnonzero((ss == "E") & (np.roll(ss, 1) != "H") & (np.roll(ss, -1) != "H"))
    rows = (strands[:, None] * k + np.arange(k)).ravel()  # (a ring's section eases over its neighbours)
    assert len(strands) > 20
    np.testing.assert_array_equal(rings[rows], spiral[rows])
    window.display_panel.cylinders.setChecked(False)
    np.testing.assert_array_equal(_rings(window, 0), spiral)

    window.display_panel.cylinders.setChecked(True)  # an edit inside a helix moves its whole cylinder
    first, last = max(helices, key=lambda h: h[1] - h[0])
    before = _rings(window, 0)
    window.rw.tug(int((first + last) // 2 // k), (2.0, -1.0, 0.5))
    edited = _rings(window, 0)
    centres = edited[first:last + 1].mean(axis=1)
    assert not np.allclose(centres, before[first:last + 1].mean(axis=1), atol=0.05)
    spread = np.linalg.svd(centres - centres.mean(axis=0), compute_uv=False)
    assert spread[1] < 1e-6 * spread[0] + 1e-9
    window.display_panel.cylinders.setChecked(False)
    window.display_panel.cylinders.setChecked(True)  # swept in full
    np.testing.assert_allclose(_rings(window, 0), edited, atol=1e-9)
