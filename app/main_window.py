"""The editor's main window: a VTK view of the structure inside a QMainWindow.

For now the view shows the Cα trace of the structure, one polyline per chain.
The ``app`` package sets ``QT_API`` before this module imports pyvistaqt.
"""

from collections.abc import Sequence
from pathlib import Path

import gemmi
import numpy as np
import pyvista as pv
from pyvistaqt import QtInteractor
from PySide6.QtGui import QAction, QCloseEvent, QKeySequence
from PySide6.QtWidgets import QMainWindow, QWidget

CA_TRACE_ACTOR = "ca_trace"
"""Name of the actor that draws the Cα trace."""


def read_ca_chains(path: Path) -> list[np.ndarray]:
    """Read the Cα trace of each polymer chain of the first model of a structure file.

    Parameters
    ----------
    path
        PDB or mmCIF file, optionally gzipped.

    Returns
    -------
    list of ndarray, shape (n_residues, 3)
        Cα coordinates in Å, one array per chain with at least two Cα atoms, in file order.

    Raises
    ------
    OSError
        The file cannot be opened.
    ValueError
        The file is not a readable structure or holds no chain with at least two Cα atoms.
    """
    try:
        structure = gemmi.read_structure(str(path))
    except OSError as error:
        raise OSError(f"cannot read {path}: {error.strerror}") from error
    except (RuntimeError, ValueError) as error:
        raise ValueError(f"cannot read {path}: {error}") from error
    structure.setup_entities()
    chains = []
    if len(structure) > 0:
        for chain in structure[0]:
            atoms = (residue.find_atom("CA", "*") for residue in chain.get_polymer())
            positions = [atom.pos.tolist() for atom in atoms if atom]
            if len(positions) >= 2:
                chains.append(np.array(positions, dtype=float))
    if not chains:
        raise ValueError(f"no chain with Cα atoms in {path}")
    return chains


def _polylines(chains: Sequence[np.ndarray]) -> pv.PolyData:
    """One polyline cell per chain; ``chains`` as returned by :func:`read_ca_chains`."""
    bounds = np.cumsum([0, *(len(chain) for chain in chains)])
    lines = np.concatenate([np.r_[stop - start, start:stop] for start, stop in zip(bounds[:-1], bounds[1:])])
    return pv.PolyData(np.concatenate(chains), lines=lines)


class MainWindow(QMainWindow):
    """Main window showing the Cα trace of a structure in a VTK view."""

    def __init__(self, path: Path, chains: Sequence[np.ndarray], parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setWindowTitle(f"ribbonwave — {path.name}")
        self.resize(1000, 750)
        self.plotter = QtInteractor(self, auto_update=False)
        self.setCentralWidget(self.plotter)
        self.plotter.set_background("white")
        self.plotter.add_mesh(
            _polylines(chains), color="steelblue", line_width=4, render_lines_as_tubes=True, name=CA_TRACE_ACTOR
        )
        self.plotter.reset_camera()

        quit_action = QAction("&Quit", self)
        quit_action.setShortcut(QKeySequence.StandardKey.Quit)
        quit_action.triggered.connect(self.close)
        self.menuBar().addMenu("&File").addAction(quit_action)

    def save_screenshot(self, path: Path) -> None:
        """Render the view and save an image of the whole window to ``path`` as PNG.

        Raises
        ------
        OSError
            The image cannot be written.
        """
        self.plotter.render()
        if not self.grab().save(str(path), "PNG"):
            raise OSError(f"cannot write {path}")

    def closeEvent(self, event: QCloseEvent) -> None:  # noqa: N802 (Qt override)
        """Release the VTK render window with the window."""
        self.plotter.close()
        super().closeEvent(event)
