"""``rw``: the editor as seen by scripts (``ribbonwave FILE --script S.py``) and the Python console.

Every method goes the way the mouse and the menus go: :meth:`EditorAPI.move` is a drag of a
control point (one undo step, regularized on release when the editor says so), the
properties set the model of an ensemble, the level slider and the segment, and files are
written as File ▸ Save writes them. Errors are exceptions, never dialogs.
"""

from __future__ import annotations

import contextlib
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Protocol

import numpy as np

from app.editor.features.export import export_view
from app.editor.measurements import central_atom
from app.editor.persistence.session import SUFFIX as SESSION_SUFFIX
from core.protein.lookup import Selected, find_atom, find_group, find_residues

if TYPE_CHECKING:
    from app.editor.docks.panels import DisplayPanel
    from app.editor.document import Document
    from app.editor.features.clipping import Clipping
    from app.editor.features.files import Files
    from app.editor.features.maps import MapsAndFits
    from app.editor.features.models import Models
    from app.editor.features.navigation import Navigation
    from app.editor.features.sessions import Sessions
    from app.editor.map_correlation import LiveCorrelation
    from app.editor.scene.view import View


class Editor(Protocol):
    """What ``rw`` drives: the editor window (:class:`~app.editor.main_window.MainWindow`)."""

    document: Document
    plotter: View
    correlation: LiveCorrelation
    files: Files
    sessions: Sessions
    navigation: Navigation
    maps_and_fits: MapsAndFits
    display_panel: DisplayPanel
    clipping: Clipping
    models: Models

    def quit_unattended(self, discard: bool = False) -> None:
        """Close without asking; unsaved edits stay in the journal unless ``discard``."""


class EditorAPI:
    """The ``rw`` object: the document of ``editor`` and what can be done with it."""

    def __init__(self, editor: Editor) -> None:
        self._editor = editor

    @property
    def _document(self) -> Document:
        document = self._editor.document
        if document.model is None:
            raise RuntimeError("no structure is open: rw.open(path) first")
        return document

    @property
    def _editable(self) -> Document:
        """The document, if it can be edited (else ValueError saying why)."""
        document = self._document
        if not document.editable:
            raise ValueError(document.read_only_reason)
        return document

    # ------------------------------------------------------------------ state

    @property
    def model(self) -> int:
        """The model of a multi-model entry shown and edited (1 .. n, in file order); it can
        change while there are no edits to undo (else ValueError)."""
        return self._document.model_number

    @model.setter
    def model(self, value: int) -> None:
        self._document.set_model_number(value)

    @property
    def level(self) -> float:
        """The level of the slider (Carson's: 0 .. log2 N of the current segment)."""
        return self._document.level

    @level.setter
    def level(self, value: float) -> None:
        self._document.set_level(float(value))

    @property
    def segment(self) -> int:
        """The segment whose control points are shown and edited (0-based)."""
        return self._document.segment

    @segment.setter
    def segment(self, value: int) -> None:
        self._document.set_segment(int(value))

    def points(self) -> np.ndarray:
        """(n, 3) control points of the curve shown (the current segment at its level), Å."""
        return self._editable.level_curve().control_points.copy()

    def coords(self) -> np.ndarray:
        """(n_atoms, 3) every atom of the edited structure, Å."""
        return self._document.model.coords.copy()

    @property
    def selection(self) -> list[str]:
        """Labels of the selected residues, then groups, e.g. ``['A:LYS48', 'A:BEN1']``."""
        document = self._document
        return Selected(document.selection, document.selected_groups).labels(document.structure)

    def go_to(self, residues: str) -> list[str]:
        """Select ``residues`` (``'A:45'``, ``'45'`` in the edited chain, ``'A:40-50'``, ``'A:40-42, B:45'``;
        ChimeraX's ``'/A:40-50'``, PyMOL's ``'chain A and resi 40-50+60'``, a binding site
        ``'byres resn HEM around 5'``, these combined, ``'chain A and ss H'``: :mod:`core.protein.lookup`),
        or a ligand, ion, water or nucleotide (``'A:HEM'``, ``'resn BEN'``, ``'/B:20'``, ``'organic'``)
        and centre and zoom the view on them, as Go to Residue (Ctrl+L) does; their chain becomes the
        edited segment. Returns the labels selected (ValueError for a residue that does not exist)."""
        return self._editor.navigation.go_to(residues).labels(self._document.structure)

    def measure(self, *atoms: int | str) -> float | None:
        """Label one atom (or, named without an atom, ``'A:48'``, its residue; ``'A:HEM'``, a
        ligand), or measure the distance of two, the angle of three or the dihedral of four, as
        View ▸ Label and the Measure tools do: atoms as coordinate rows or as people name them
        (``'A:48 NZ'``, ``'/A:48@NZ'``, ``'A/48/NZ'``, ``'/A:HEM@FE'``; in the edited chain where
        none is named). Returns the value (Å or degrees; None for a label)."""
        document = self._document
        chain = document.structure.segments[document.segment].chain if document.editable else None
        if len(atoms) == 1 and isinstance(atoms[0], str):
            rows = []
            if document.editable:
                with contextlib.suppress(ValueError):  # not a residue: a group, or an atom, below
                    rows = find_residues(document.structure, atoms[0], chain)
            if len(rows) == 1:  # a residue: its label
                document.measurements.add([int(document.ca_rows[rows[0]])], len(document.model.coords), True)
                return None
            group = None if len(rows) else find_group(document.structure, atoms[0], chain)
            if group is not None:  # a ligand, ion, water or nucleotide: its label, on its central atom
                coords = document.model.coords
                document.measurements.add([central_atom(coords, group)], len(coords), True)
                return None
        rows = [int(atom) if isinstance(atom, (int, np.integer)) else find_atom(document.structure, atom, chain)
                for atom in atoms]
        return document.measurements.add(rows, len(document.model.coords)).value(document.model.coords)

    @property
    def measurements(self) -> list[str]:
        """Each label and measurement as the *Measurements* dock lists it, its value as the
        model is now: ``'A:LYS48 NZ – A:GLU50 OE1: 3.21 Å'``."""
        document = self._document
        return [m.names(document.structure) + ("" if m.kind == "label" else
                                                f": {m.text(document.structure, document.model.coords)}")
                for m in document.measurements.items]

    def show(self, *layers: str, on: bool = True) -> None:
        """Show (or with ``on=False`` hide) layers as the *Display* dock's boxes do, named as
        ``--hide`` names them: ``'cartoon'``, ``'tube'``, ``'nucleic-acids'``, ``'other-models'``, ..."""
        boxes = self._editor.display_panel.layer_boxes
        for name in layers:
            layer = next((layer for layer in boxes if layer.name.lower().replace("_", "-") == name), None)
            if layer is None:
                known = ", ".join(layer.name.lower().replace("_", "-") for layer in boxes)
                raise ValueError(f"no layer {name!r}; layers: {known}")
            boxes[layer].setChecked(on)

    @property
    def cylinders(self) -> bool:
        """Whether the cartoon's helices are cylinders (the *Display* dock's box); settable."""
        return self._editor.display_panel.cylinders.isChecked()

    @cylinders.setter
    def cylinders(self, on: bool) -> None:
        self._editor.display_panel.cylinders.setChecked(bool(on))

    @property
    def slab(self) -> tuple[float, float] | None:
        """The clipping slab, Å in front of and behind the centre of the view, or None (View ▸
        Clip Slab); settable."""
        return self._editor.clipping.scene.slab

    @slab.setter
    def slab(self, slab: tuple[float, float] | None) -> None:
        self._editor.clipping.set(None if slab is None else (float(slab[0]), float(slab[1])))

    def play_models(self, on: bool = True) -> None:
        """Start (or stop) showing the models of an ensemble in turn, as View ▸ Play Models does."""
        self._editor.models.play(on)

    def history(self) -> tuple[list[str], int]:
        """The names of the undo steps and the current position (steps done)."""
        stack = self._document.undo_stack
        return [stack.text(k) for k in range(stack.count())], stack.index()

    # ------------------------------------------------------------------ edits

    def move(self, index: int, delta: object) -> None:
        """Drag control point ``index`` of the curve shown by ``delta`` (Å): one undo step."""
        document = self._editable
        points = document.level_curve().control_points
        if not 0 <= int(index) < len(points):
            raise IndexError(f"control point {index} does not exist: the curve shown has {len(points)}")
        document.pick_point(int(index))
        document.preview_move(int(index), _vector(delta))
        document.finish_drag(f"Move point {int(index)} at level {document.shown_level():.2f}")

    def tug(self, residue: int | str, delta: object) -> None:
        """Tug the curve shown at ``residue`` (index in the segment, or a residue of it as Go to
        Residue reads it: ``'A:LYS48'``, ``'A:31B'``, ``'48'``) by ``delta`` (Å): one undo step,
        as *Tug the curve* does."""
        document = self._editable
        labels = document.labels()
        index = _residue_index(document, residue)
        document.preview_tug(float(document.paths[document.segment].residue_u[index]), _vector(delta))
        document.finish_drag(f"Tug curve at {labels[index]} at level {document.shown_level():.2f}")

    def fit_to_map(self, levels: int | Sequence[int] | None = None, resolution: float | None = None
                   ) -> list[tuple[int, float]]:
        """Fit the edited chain into the open map as Edit ▸ Fit to Map does: at level ``levels``
        (an integer), at each of ``levels`` in turn, or (None) coarse to fine from level 0 up to
        the one shown; each level one undo step, and a fit of more than one level settled as
        on the command line (regularized, the finest levels that leave bad junctions undone)
        and refined (each residue and its side chains), a step each. ``resolution`` (Å) sets the map's resolution
        first. Returns each level kept and the correlation after it; coarse to fine (None) the
        first is -1, the chain's smaller dynamic domain moved as a rigid body before level 0
        (:mod:`core.fitting.domains`)."""
        if resolution is not None:
            self._editor.correlation.set_resolution(float(resolution))
        return self._fit("map", levels)

    def fit_to_compared(self, levels: int | Sequence[int] | None = None) -> list[tuple[int, float]]:
        """Fit the edited chain onto the (first shown) compared structure as Edit ▸ Fit to
        Compared Structure does (``levels`` as for :meth:`fit_to_map`). Returns each level
        fitted and the Cα rmsd to the target after it (Å)."""
        return self._fit("compared", levels)

    def _fit(self, target: str, levels: int | Sequence[int] | None) -> list[tuple[int, float]]:
        self._editable
        chosen = None if levels is None else [int(levels)] if isinstance(levels, (int, np.integer)) else \
            [int(level) for level in levels]
        fits = self._editor.maps_and_fits.fit(target, True, chosen, raise_errors=True)
        return [(fit.level, fit.score) for fit in fits]

    @property
    def map_correlation(self) -> float | None:
        """The correlation of the edited segment with the open map (None without a map)."""
        self._document
        correlation = self._editor.correlation
        correlation.update()
        if correlation.message:
            raise ValueError(correlation.message)
        return correlation.value

    def undo(self) -> None:
        """Undo the last step (as Ctrl+Z)."""
        self._editor.document.undo_stack.undo()

    def redo(self) -> None:
        """Redo the next step (as Ctrl+Shift+Z)."""
        self._editor.document.undo_stack.redo()

    # ------------------------------------------------------------------ files

    def open(self, path: str | Path) -> None:
        """Open a structure (PDB or mmCIF) or a session (``.rwsession``)."""
        path = Path(path)
        if path.name.endswith(SESSION_SUFFIX):
            self._editor.sessions.open_session(path, raise_errors=True)
        else:
            self._editor.files.open_file(path, raise_errors=True)

    def open_map(self, path: str | Path, columns: tuple[str, str] | None = None) -> None:
        """Show a density map (CCP4/MRC, optionally gzipped), or an MTZ file's maps (of
        ``columns``, amplitude and phase, else those refinement names 2mFo−DFc and mFo−DFc),
        as File ▸ Open Map… does (raises :class:`core.surfaces.volume.MapError` for a file
        that is not one)."""
        self._editor.maps_and_fits.open_map(Path(path), columns, raise_errors=True)

    def export(self, path: str | Path, *, overwrite: bool = False) -> Path:
        """Write the structure as edited (PDB or mmCIF by the extension) without making
        ``path`` the document's file or marking the edits saved."""
        return self._document.model.save(Path(path), overwrite=overwrite)

    def save(self, path: str | Path, *, overwrite: bool = False) -> Path:
        """Save as File ▸ Save As does: ``path`` becomes the document's file, the edits are saved."""
        return self._document.save(Path(path), overwrite=overwrite)

    def save_session(self, path: str | Path, *, overwrite: bool = False) -> Path:
        """Save the session (structure, undo history, view) to ``path`` (``.rwsession`` added if
        missing); an existing file only with ``overwrite`` (else FileExistsError)."""
        return self._editor.sessions.write_session(Path(path), overwrite=overwrite)

    def screenshot(self, path: str | Path, width: int | None = None, height: int | None = None, *,
                   supersample: int = 1, transparent: bool = False, overwrite: bool = False) -> Path:
        """Save the 3D view as a PNG image as File ▸ Export Image does: ``width`` x ``height``
        pixels (one given: the other by the view's aspect ratio; none: the view's size), rendered
        ``supersample`` (1, 2 or 4) times larger and averaged down, on a transparent background
        if ``transparent``."""
        return export_view(self._editor.plotter, Path(path), width, height, supersample=supersample,
                           transparent=transparent, overwrite=overwrite)

    def quit(self, discard: bool = False) -> None:
        """Close the editor. Unsaved edits stay in the recovery journal unless ``discard``."""
        self._editor.quit_unattended(discard)


def _vector(delta: object) -> np.ndarray:
    vector = np.asarray(delta, dtype=np.float64).reshape(-1)
    if vector.shape != (3,) or not np.all(np.isfinite(vector)):
        raise ValueError(f"delta must be three finite numbers (Å); got {delta!r}")
    return vector


def _residue_index(document: Document, residue: int | str) -> int:
    """Index in the edited segment of ``residue``: an index, or a residue as Go to Residue
    reads it (``'A:LYS48'``, ``'A:31B'``, ``'48A'``, ``'/A:48'``; in the edited chain where
    none is named)."""
    labels = document.labels()
    if isinstance(residue, (int, np.integer)):
        if not 0 <= residue < len(labels):
            raise IndexError(f"residue {residue} does not exist: the segment has {len(labels)}")
        return int(residue)
    segment = document.structure.segments[document.segment]
    rows = find_residues(document.structure, str(residue), segment.chain)
    index = int(rows[0]) - int(segment.residue_index[0])
    if len(rows) != 1 or not 0 <= index < len(segment):
        raise ValueError(f"{str(residue).strip()!r} is not one residue of the edited segment ({labels[0]}–{labels[-1]})")
    return index
