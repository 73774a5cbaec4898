"""Biological assemblies in the editor: File ▸ Open Biological Assembly and ``--assembly N``."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from PySide6.QtWidgets import QInputDialog, QMessageBox
from pytestqt.qtbot import QtBot

from app.editor.main_window import MainWindow
from app.main import main
from tests.conftest import DATA

Opener = Callable[[str], MainWindow]


def test_the_menu_opens_a_chosen_assembly_and_draws_every_chain(open_window: Opener, qtbot: QtBot,
                                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    window = open_window("3JQH.cif.gz")
    offered: list[list[str]] = []

    def choose(parent, title, label, items, current, editable):  # (as QInputDialog.getItem)
        offered.append(list(items))
        return items[0], True

    monkeypatch.setattr(QInputDialog, "getItem", choose)
    window.files.assembly_action.trigger()
    assert offered == [["assembly 1: 24 chains, 5,712 atoms (24-meric)"]]
    document = window.document
    assert document.path == DATA / "3JQH-assembly1.cif" and document.structure.n_atoms == 5712
    assert len(document.structure.segments) == 24 and document.save_path is None and not document.modified
    assert window.windowTitle().startswith("3JQH-assembly1.cif")
    window.plotter.render()
    bounds = np.array(window.scene.actors["cartoon"].bounds).reshape(3, 2)
    ca = document.structure.atoms.coords[document.structure.atoms.name == "CA"]
    assert np.allclose(bounds[:, 0], ca.min(axis=0), atol=3.0) and np.allclose(bounds[:, 1], ca.max(axis=0), atol=3.0)
    assert not (DATA / "3JQH-assembly1.cif").exists()  # nothing written until saved

    answers: list[str] = []
    monkeypatch.setattr(QMessageBox, "information", lambda parent, title, text: answers.append(text))
    window.files.assembly_action.trigger()  # an assembly has no assembly records of its own
    assert answers == [("3JQH-assembly1.cif has no biological assembly records (REMARK 350 or "
                        "_pdbx_struct_assembly).")] and len(offered) == 1


def test_command_line_assembly(qtbot: QtBot, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    report = tmp_path / "report.json"
    script = tmp_path / "report.py"
    script.write_text("import json, pathlib\n"
                      f"pathlib.Path({str(report)!r}).write_text(json.dumps([rw._editor.document.title, "
                      "[s.chain for s in rw._editor.document.structure.segments]]))\n")
    assert main([str(DATA / "2HPR_A.pdb.gz"), "--assembly", "2", "--script", str(script)]) == 0
    title, chains = json.loads(report.read_text())
    assert title == "2HPR_A-assembly2.cif" and sorted(set(chains)) == ["A1", "A2"]
    assert main([str(DATA / "3JQH.cif.gz"), "--assembly", "2", "--script", str(script)]) == 1
    assert capsys.readouterr().err.splitlines()[-1].endswith("3JQH.cif.gz: no assembly 2; the file has assemblies "
                                                            "1 to 1")
