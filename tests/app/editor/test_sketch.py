"""The molecule sketched while the editor loads: its trace as the structure's segments, seen from
the 3D view's first direction, drawn in the ribbon's colours."""

from __future__ import annotations

import gzip
import math
from pathlib import Path

import numpy as np
import pytest
from PySide6.QtGui import QColor
from pytestqt.qtbot import QtBot

from app.editor import sketch
from app.editor.main_window import MainWindow
from app.editor.scene.looks import BACKGROUND, SS_COLOURS
from app.editor.scene.nucleic import GAP
from app.editor.sketch import LONGEST_STEP, Sketch, read_trace
from core.protein.reading import read_atoms, read_structure
from core.protein.structure import MAX_CA_STEP
from tests.conftest import DATA


@pytest.mark.parametrize("name", ["1UBQ.pdb.gz", "4HHB.pdb.gz", "1AM7.pdb.gz", "7Z9T.cif.gz", "2K39_CA-only.pdb.gz"])
def test_the_trace_runs_as_the_structure_segments_in_their_secondary_structure(name: str) -> None:
    """Each run of the trace is a segment of the structure as the editor reads it (cut at the same
    gaps), its Cα at the same places, its helices and strands those of the file's records."""
    structure = read_structure(DATA / name)
    trace = read_trace(DATA / name)
    assert trace is not None and LONGEST_STEP["protein"] == MAX_CA_STEP
    runs = [run for run in trace.runs if "N" not in run.kinds]
    assert [len(run.positions) for run in runs] == [len(segment) for segment in structure.segments]
    for run, segment in zip(runs, structure.segments):
        assert run.kinds == "".join(segment.ss)
        np.testing.assert_allclose(np.array(run.positions), segment.ca, atol=1e-3)


def test_the_model_asked_for_is_traced() -> None:
    trace, structure = read_trace(DATA / "1L2Y.pdb.gz", model=7), read_structure(DATA / "1L2Y.pdb.gz", model=7)
    np.testing.assert_allclose(np.array(trace.runs[0].positions), structure.segments[0].ca, atol=1e-3)
    assert not np.allclose(np.array(read_trace(DATA / "1L2Y.pdb.gz").runs[0].positions), structure.segments[0].ca)


def test_nucleic_acids_are_traced_through_their_phosphates() -> None:
    """As the view's tube: through each nucleotide's P (C4' where it has none), strands apart."""
    trace = read_trace(DATA / "1BNA.pdb.gz")  # a B-DNA dodecamer: two strands, the first of each without P
    assert trace is not None and [(len(run.positions), run.kinds) for run in trace.runs] == [(12, "N" * 12)] * 2
    steps = [math.dist(a, b) for run in trace.runs for a, b in zip(run.positions, run.positions[1:])]
    assert 3.5 < min(steps) and max(steps) < LONGEST_STEP["nucleic"] == GAP  # (C4' to P the shortest)
    assert len(trace.looked_at) == len(read_atoms(DATA / "1BNA.pdb.gz").coords)  # no protein: every atom, as the view


def test_what_cannot_be_read_is_not_sketched(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Garbage, an empty file, a folder, a missing file, water alone or a file beyond the input
    limit: no sketch (opening the file then says why); nor a file too large to read twice."""
    garbage, empty, water, big = (tmp_path / name for name in ("garbage.pdb", "empty.cif", "water.pdb", "big.pdb.gz"))
    garbage.write_bytes(b"\x00\xff not a structure at all\n" * 20)
    empty.write_text("")
    water.write_text("HETATM    1  O   HOH A   1       0.000   0.000   0.000  1.00  0.00           O\nEND\n")
    big.write_bytes(gzip.compress(b"REMARK" + b" " * 3_000_000))
    monkeypatch.setenv("RIBBONWAVE_MAX_INPUT_MB", "1")
    for path in (garbage, empty, water, big, tmp_path, tmp_path / "missing.pdb"):
        assert read_trace(path) is None, path
    assert read_trace(DATA / "1UBQ.pdb.gz") is not None
    assert read_trace(DATA / "1UBQ.pdb.gz", model=2) is None and read_trace(DATA / "1UBQ.pdb.gz", model=0) is None
    monkeypatch.setattr(sketch, "LARGEST_SKETCHED", (DATA / "1UBQ.pdb.gz").stat().st_size - 1)
    assert read_trace(DATA / "1UBQ.pdb.gz") is None


@pytest.mark.parametrize("name", ["1UBQ.pdb.gz", "4HHB.pdb.gz", "7Z9T.cif.gz", "1BNA.pdb.gz"])
def test_the_sketch_looks_from_where_the_view_first_looks(qtbot: QtBot, name: str) -> None:
    """The sketch's camera looks in the direction, and with the up, of the 3D view's first camera
    on the structure, so the view that replaces it shows the molecule turned the same way."""
    window = MainWindow()
    qtbot.addWidget(window)
    window.document.open(DATA / name)
    camera = window.plotter.renderer.GetActiveCamera()
    view = read_trace(DATA / name).camera(window.plotter.width() / window.plotter.height())
    assert np.dot(camera.GetDirectionOfProjection(), view.towards) == pytest.approx(-1.0, abs=1e-6)
    assert np.dot(camera.GetViewUp(), view.up) == pytest.approx(1.0, abs=1e-6)


def test_the_sketch_draws_the_molecule_in_the_middle_in_ribbon_colours(qtbot: QtBot) -> None:
    """Before a trace: the view's background alone. With ubiquitin's: its helices and strands in
    the ribbon's colours, the drawing centred, filling much of the height without leaving the view."""
    sketch = Sketch()
    qtbot.addWidget(sketch)
    sketch.resize(800, 600)
    blank = sketch.grab().toImage()
    colours = {blank.pixelColor(x, y).name() for x in range(0, 800, 40) for y in range(0, 600, 40)}
    assert len(colours) > 3 and all(_near(QColor(c), BACKGROUND, 40) for c in colours)  # (a gradient)
    sketch.draw(read_trace(DATA / "1UBQ.pdb.gz"))
    image = sketch.grab().toImage()
    drawn = np.array([[x, y] for x in range(0, 800, 4) for y in range(0, 600, 4)
                      if not _near(image.pixelColor(x, y), BACKGROUND, 12)])
    kinds = {kind: sum(_near(image.pixelColor(x, y), [QColor(*rgb).name()], 30) for x, y in drawn)
             for kind, rgb in SS_COLOURS.items()}
    assert kinds["H"] > 100 and kinds["E"] > 100 and kinds["C"] > 50
    assert np.all(np.abs(drawn.mean(axis=0) - [400, 300]) < 60)
    height = np.ptp(drawn[:, 1])
    assert 250 < height < 600 and drawn[:, 0].min() > 0 and drawn[:, 0].max() < 796


def _near(colour: QColor, names: list[str] | tuple[str, ...], tolerance: int) -> bool:
    """Whether ``colour`` lies within ``tolerance`` (each channel) of the span of ``names``' colours."""
    channels = [(QColor(name).red(), QColor(name).green(), QColor(name).blue()) for name in names]
    return all(min(c[k] for c in channels) - tolerance <= value <= max(c[k] for c in channels) + tolerance
               for k, value in enumerate((colour.red(), colour.green(), colour.blue())))
