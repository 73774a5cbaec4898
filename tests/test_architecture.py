"""The architecture holds: the import-linter contracts of pyproject.toml (core in layers, no GUI in
core, the command line and the editor apart), no import circle in app or core, and the headless
commands load no GUI package."""

import json
import subprocess
import sys
from pathlib import Path

import grimp
import pytest

ROOT = Path(__file__).resolve().parent.parent
GUI_PACKAGES = ("PySide6", "vtk", "vtkmodules", "pyvista", "pyvistaqt", "qtpy", "matplotlib")


def test_import_linter_contracts_hold() -> None:
    lint_imports = Path(sys.executable).parent / "lint-imports"
    result = subprocess.run(
        [str(lint_imports), "--no-cache"], cwd=ROOT, capture_output=True, text=True, check=False
    )
    assert result.returncode == 0, result.stdout + result.stderr


def test_no_import_circle_in_app_or_core() -> None:
    """No import circle among the modules of app and core, imports under TYPE_CHECKING included:
    each module can be read, and changed, before the modules it imports."""
    graph = grimp.build_graph("app", "core", cache_dir=None)
    circles: dict[frozenset[str], tuple[str, ...]] = {}
    for importer in sorted(graph.modules):
        for imported in sorted(graph.find_modules_directly_imported_by(importer)):
            back = graph.find_shortest_chain(importer=imported, imported=importer)
            if back is not None:
                circles.setdefault(frozenset(back), (importer, *back))
    assert not circles, "import circles:\n" + "\n".join(" -> ".join(circle) for circle in circles.values())


def test_importing_all_of_core_loads_no_gui_package() -> None:
    script = f"""
import importlib, json, pkgutil, sys
import core
for module in pkgutil.walk_packages(core.__path__, "core."):
    importlib.import_module(module.name)
loaded = {{name.partition(".")[0] for name in sys.modules}}
print(json.dumps(sorted(loaded & set({GUI_PACKAGES!r}))))
"""
    result = subprocess.run(
        [sys.executable, "-c", script], cwd=ROOT, capture_output=True, text=True, check=False
    )
    assert result.returncode == 0, result.stderr
    assert json.loads(result.stdout) == []


@pytest.mark.parametrize("command", [
    ["info", "resources/examples/1UBQ.pdb"],
    ["curve", "resources/examples/1UBQ.pdb", "--level", "3", "--csv"],
    ["edit", "resources/examples/1UBQ.pdb", "--chain", "A", "--level", "3", "--point", "5", "--move", "4,0,0",
     "--regularize", "-o", "{out}"],
    ["validate", "resources/examples/1UBQ.pdb", "--json"],
])
def test_headless_commands_load_no_gui_package(command: list[str], tmp_path: Path) -> None:
    """``ribbonwave info``, ``curve``, ``edit`` and ``validate`` run without Qt, VTK or matplotlib."""
    argv = [arg.replace("{out}", str(tmp_path / "bent.pdb")) for arg in command]
    script = f"""
import contextlib, io, json, sys
from app.main import main
with contextlib.redirect_stdout(io.StringIO()):
    status = main({argv!r})
loaded = {{name.partition(".")[0] for name in sys.modules}}
print(json.dumps([status, sorted(loaded & set({GUI_PACKAGES!r}))]))
"""
    result = subprocess.run(
        [sys.executable, "-c", script], cwd=ROOT, capture_output=True, text=True, check=False
    )
    assert result.returncode == 0, result.stderr
    assert json.loads(result.stdout) == [0, []]


def test_test_modules_have_unique_names() -> None:
    """pytest imports test modules by their base name (the tests have no packages): two files
    of one name in different folders stop the whole run at collection."""
    names = [path.name for path in (ROOT / "tests").rglob("test_*.py")]
    assert sorted(name for name in set(names) if names.count(name) > 1) == []
