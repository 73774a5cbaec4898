"""The document: the one owner of the structure being edited (a QObject without widgets).

It holds the :class:`~core.protein.model.EditableModel`, the slider level, the chosen segment, the
picked control point, the file names and the undo stack. Only its mutators change that
state, and each emits a signal that says what changed, so views can subscribe and touch
only what they must. Every edit reaches the model through an undo command
(:class:`app.editor.commands.EditCommand`); a drag shows previews relative to the state at the
start of the gesture and pushes one command when it ends. Journals and sessions record the
document and replay it (:mod:`app.editor.persistence.recording`) inside :meth:`Document.rebuilding`.

A document holds one model of its file (:attr:`model_number`; another can be chosen while
there are no edits to undo). A structure without a protein backbone (DNA) opens for
viewing only (:attr:`editable` False): the mutators that need a segment raise ValueError
with :attr:`read_only_reason`, and ``levelChanged``, ``segmentChanged``, ``picked`` and
``changed`` never come, so views check :attr:`editable` only when a structure is loaded.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import NamedTuple

import numpy as np
from PySide6.QtCore import QObject, QSignalBlocker, Signal
from PySide6.QtGui import QUndoStack

from app.editor.history import History
from app.editor.measurements import Measurements
from app.editor.scene.curves import LevelCurve, SegmentPath, segment_paths
from core.geometry.regularize import FLANK, regularize_region, regularized
from core.protein.assembly import assembly_path, assembly_text
from core.protein.input_files import read_bytes
from core.protein.lookup import Selected
from core.protein.model import Edit, EditableModel
from core.protein.reading import read_structure
from core.protein.ribbon import RibbonKind
from core.protein.structure import Structure, ca_rows

LEVELS_BELOW_MAX = 2
"""A file opens at the integer level nearest to ``log2 N - 2`` (a quarter of the detail:
Carson's colleagues still recognised the fold there)."""


class Change(NamedTuple):
    """What one edit (or its undo) moved."""

    segment: int
    residues: np.ndarray
    """Residue indices within the segment."""
    rows: np.ndarray
    """Rows of the coordinate array."""


class Pick(NamedTuple):
    """A picked control point of the curve shown at the current level."""

    index: int
    residues: np.ndarray
    """Residues (within the segment) that moving it would move."""


class Document(QObject):
    """The edited structure and everything the views show about it."""

    loaded = Signal()
    """A structure was opened (or the ribbon kind changed): everything is new."""
    changed = Signal(object)
    """A :class:`Change`: atoms and the ribbon of one segment moved."""
    levelChanged = Signal()
    """The slider level or the multiresolution switch changed."""
    segmentChanged = Signal()
    picked = Signal()
    """The picked control point changed (see :attr:`pick`)."""
    fileChanged = Signal()
    """The file name, the save target or the modified state changed."""
    selectionChanged = Signal()
    """The selected residues or groups changed (see :attr:`selection`, :attr:`selected_groups`)."""
    saved = Signal()  # (by :meth:`save`)

    def __init__(self, parent: QObject | None = None) -> None:
        super().__init__(parent)
        self.undo_stack = QUndoStack(self)
        self.undo_stack.cleanChanged.connect(self.fileChanged)
        self.history = History(self)  # (steps are pushed there; undone and redone on the stack)
        self.model: EditableModel | None = None
        self.paths: list[SegmentPath] = []
        self.ca_rows = np.empty(0, dtype=np.int64)
        """Row of the coordinates holding each backbone residue's Cα (residue-table order)."""
        self.path: Path | None = None
        self.source = b""
        """The file's bytes as read (journals and sessions embed them)."""
        self.replaying = False
        """Whether a recording is being replayed (:meth:`rebuilding`): its steps are not new."""
        self.save_path: Path | None = None
        """Where Save writes without asking; None until Save As chose a file."""
        self.segment = 0
        self.level = 0.0
        self.multiresolution = True
        self.pick: Pick | None = None
        self.selection = np.empty(0, dtype=np.int64)
        """Selected residues: rows of the residue table, sorted (any segments)."""
        self.selected_groups = np.empty(0, dtype=np.int64)
        """Selected ligands, ions, waters and nucleotides: coordinate rows of whole groups, sorted."""
        self.regularize_on_release = True
        """A drag's undo step holds the edit followed by :func:`core.geometry.regularize.regularized`."""
        self.regularize_while_dragging = False
        """Every preview is regularized (40–110 ms a step on ubiquitin: off by default)."""
        self.carry_ligands = True
        """Edits carry the ligands and ions bound to the residues they move (see :meth:`set_carry_ligands`)."""
        self._curves: dict[int, LevelCurve] = {}
        self._preview: Edit | None = None
        self.measurements = Measurements(self)
        """Labels and measurements on atoms (cleared with a new structure)."""
        self.kept_view = False
        """Whether the structure last loaded is another model of the same file, shown as the
        one before it was (the camera and the slab stay)."""

    # ------------------------------------------------------------------ state

    @property
    def structure(self) -> Structure:
        return self._model.structure

    @property
    def kind(self) -> RibbonKind:
        return self._model.kind

    @property
    def model_number(self) -> int:
        """The model of the file shown and edited, 1 .. ``structure.n_models``."""
        return self.structure.model_number

    @property
    def editable(self) -> bool:
        """Whether the structure has a backbone segment to edit (else it is only viewed)."""
        return self.model is not None and bool(self._model.ribbons)

    @property
    def read_only_reason(self) -> str:
        """Why the open structure cannot be edited ('' when it can)."""
        if self.model is None or self.editable:
            return ""
        return f"{self.structure.entry_id} has no protein backbone: viewing only"

    @property
    def title(self) -> str:
        """The file's name, with the model for a multi-model entry: ``'1L2Y.pdb.gz (model 3 of 38)'``."""
        name = self.path.name if self.path is not None else "untitled"
        several = self.model is not None and self.structure.n_models > 1
        return f"{name} (model {self.model_number} of {self.structure.n_models})" if several else name

    @property
    def modified(self) -> bool:
        """Edits not saved yet."""
        return self.model is not None and not self.undo_stack.isClean()

    @property
    def max_level(self) -> float:
        """Top of the slider for the current segment, ``log2 N`` (0 without segments)."""
        return self._model.ribbons[self.segment].max_level if self.editable else 0.0

    def shown_level(self, segment: int | None = None) -> float:
        """Level at which ``segment`` (default: the current one) is shown and edited."""
        ribbon = self._model.ribbons[self.segment if segment is None else segment]
        return min(self.level, ribbon.max_level) if self.multiresolution else ribbon.max_level

    def level_curve(self, segment: int | None = None) -> LevelCurve:
        """The curve of ``segment`` (default: the current one) at its shown level (cached)."""
        segment = self.segment if segment is None else segment
        if segment not in self._curves:
            ribbon = self._model.ribbons[segment]
            self._curves[segment] = self.paths[segment].level_curve(ribbon, self.shown_level(segment))
        return self._curves[segment]

    def deviation(self) -> float:
        """rms |Cα − C^r| (Å) of the current segment at its shown level, with the current Cα positions."""
        ca = self._model.coords[self.ca_rows[self.structure.segments[self.segment].residue_index]]
        offset = self.level_curve().residue_points - ca
        return float(np.sqrt(np.mean(np.einsum("ij,ij->i", offset, offset))))

    def labels(self) -> tuple[str, ...]:
        """Residue labels of the current segment, e.g. ``'A:LYS48'``."""
        return self.structure.segments[self.segment].labels

    def residue_range(self, residues: np.ndarray) -> str:
        """``residues`` of the current segment in a few words: ``'A:LYS6–A:THR9'`` (or ``'none'``)."""
        if len(residues) == 0:
            return "none"
        first, last = (self.labels()[int(residues[k])] for k in (0, -1))
        return first if first == last else f"{first}–{last}"

    # ------------------------------------------------------------------ mutators

    def open(self, path: Path, kind: RibbonKind | str = RibbonKind.PEPTIDE, data: bytes | None = None,
             model: int = 1, assembly: int | None = None) -> None:
        """Read model ``model`` (1 .. n, in file order) of ``path`` (or of its content ``data``,
        already read) and make it the document (raises :class:`core.protein.input_files.StructureError`).
        A structure without protein opens for viewing only (see :attr:`editable`). With
        ``assembly``, its biological assembly of that number (from 1), built from that model, is
        the document, as the mmCIF file :func:`~core.protein.assembly.assembly_path` names."""
        data = read_bytes(path) if data is None else data
        if assembly is not None:
            data = assembly_text(path, data, number=assembly, model=model).encode()
            path, model = assembly_path(path, assembly), 1
        self._set_model(EditableModel(read_structure(path, data, model=model, require_protein=False), kind))
        self.path = Path(path)
        self.source = data
        self.save_path = None
        self.fileChanged.emit()

    def set_kind(self, kind: RibbonKind | str) -> None:
        """Switch between the peptide-plane and the Cα ribbon; only without edits to undo."""
        if RibbonKind(kind) is self.kind:
            return
        if self.undo_stack.index() > 0:
            raise ValueError("the ribbon kind can change only while there are no edits to undo")
        self._set_model(EditableModel(self.structure, kind))

    def set_model_number(self, number: int) -> None:
        """Show and edit model ``number`` (1 .. n) of the file instead, at the same segment and
        level; only without edits to undo (else ValueError; StructureError for a model the
        file does not have)."""
        if number == self.model_number:
            return
        if self.undo_stack.index() > 0:
            raise ValueError("another model can be chosen only while there are no edits to undo")
        structure = read_structure(self.structure.path, self.source, model=number, require_protein=False)
        self._set_model(EditableModel(structure, self.kind), keep_view=True)
        self.fileChanged.emit()

    def set_level(self, level: float) -> None:
        """Set the slider level (clipped to ``[0, log2 N]`` of the current segment)."""
        self._check_editable()
        level = float(np.clip(level, 0.0, self.max_level))
        if level != self.level:
            self.level = level
            self._level_changed()

    def set_multiresolution(self, on: bool) -> None:
        """Multiresolution analysis on (the slider level) or off (every segment at full resolution)."""
        self._check_editable()
        if on != self.multiresolution:
            self.multiresolution = on
            self._level_changed()

    def set_segment(self, segment: int) -> None:
        """Choose the segment whose control points are shown and edited, at the same depth
        below its top level as the one before (the same share of the detail left out)."""
        self._check_editable()
        if not 0 <= segment < len(self._model.ribbons):
            raise ValueError(f"segment must be in [0, {len(self._model.ribbons) - 1}]; got {segment}")
        if segment != self.segment:
            below_top = self.max_level - self.shown_level()  # the detail left out, kept (not the level)
            self.segment = segment
            self.level = max(0.0, self.max_level - below_top)
            self._set_pick(None)
            self.segmentChanged.emit()
            self._level_changed()

    def pick_point(self, index: int | None) -> None:
        """Pick control point ``index`` of the current level curve (None: nothing)."""
        if index is None:
            self._set_pick(None)
            return
        self._check_editable()
        self._set_pick(Pick(index, self.point_residues(index)))

    def point_residues(self, index: int) -> np.ndarray:
        """Residues (within the current segment) that moving control point ``index`` of the
        current level curve would move."""
        return self._model.move_point(self.segment, self.shown_level(), index, np.array([1.0, 0.0, 0.0])).residues

    def select(self, rows: np.ndarray | list[int], groups: np.ndarray | list[int] = ()) -> None:
        """Select residues by residue-table row and groups outside the backbone segments by
        coordinate row (none: an empty selection; ValueError: :meth:`Selected.of`)."""
        new = Selected.of(self.structure, rows, groups)
        if not (np.array_equal(new.residues, self.selection) and np.array_equal(new.groups, self.selected_groups)):
            self.selection, self.selected_groups = new.residues, new.groups
            self.selectionChanged.emit()

    @property
    def dragging(self) -> bool:
        """Whether a drag's edit is being previewed (not yet an undo step)."""
        return self._preview is not None

    def preview_move(self, index: int, displacement: np.ndarray) -> None:
        """Show control point ``index`` moved by ``displacement`` (Å) from where the drag began."""
        self._preview_edit(lambda: self._model.move_point(self.segment, self.shown_level(), index, displacement))

    def preview_tug(self, u: float, displacement: np.ndarray) -> None:
        """Show the level curve dragged at parameter ``u`` by ``displacement`` (Å) from the drag start."""
        self._preview_edit(lambda: self._model.tug(self.segment, self.shown_level(), u, displacement))

    def set_carry_ligands(self, on: bool) -> None:
        """Whether the ligands and ions bound to a residue move with it in the edits to come
        (:meth:`core.protein.model.EditableModel.bound_ligands`)."""
        self.carry_ligands = on
        if self.model is not None:
            self._model.carry_ligands = on

    def set_regularization(self, *, on_release: bool | None = None, while_dragging: bool | None = None) -> None:
        """Regularize drags when they end and/or at every preview (None: leave as it is)."""
        if on_release is not None:
            self.regularize_on_release = on_release
        if while_dragging is not None:
            self.regularize_while_dragging = while_dragging

    def finish_drag(self, text: str) -> None:
        """End a drag: the previewed edit (regularized if asked) becomes one undo step named
        ``text`` (none if nothing moved)."""
        edit, self._preview = self._preview, None
        if edit is not None and not np.array_equal(edit.old_points, edit.new_points):
            if self.regularize_on_release and not self.regularize_while_dragging:  # else the preview is regularized
                edit = regularized(self._model, edit)
            self.history.push(edit, text)

    def cancel_drag(self) -> None:
        """End a drag without an edit: put everything back where it was."""
        edit, self._preview = self._preview, None
        if edit is not None:
            self.revert_edit(edit)

    def regularize_region(self, residues: np.ndarray) -> None:
        """Regularize ``residues`` (indices within the current segment) and up to FLANK neighbours
        on each side as one undo step: ideal junctions, on the current curve, and no clash
        that the structure as read did not have."""
        self._check_editable()
        edit = regularize_region(self._model, self.segment, residues, flank=FLANK)
        if not np.array_equal(edit.old_coords, edit.new_coords):
            self.history.push(edit, f"Regularize {self.residue_range(edit.residues)}")

    def push_applied(self, edits: Sequence[Edit], text: str) -> None:
        """Make ``edits``, which a fit already applied to the model, one undo step named ``text``."""
        for edit in reversed(edits):
            self._model.revert(edit)
        self.history.push(edits, text)

    def apply_edit(self, edit: Edit) -> None:
        """Carry out ``edit`` (undo commands call this)."""
        self._model.apply(edit)
        self._edited(Change(edit.segment, edit.residues, edit.rows))

    def revert_edit(self, edit: Edit) -> None:
        """Undo ``edit`` exactly (undo commands call this)."""
        self._model.revert(edit)
        self._edited(Change(edit.segment, edit.residues, edit.rows))

    def save(self, path: Path, *, overwrite: bool = False) -> Path:
        """Write the edited structure (PDB or mmCIF by the extension) atomically; it becomes the
        document's file and Save's target. Raises StructureError, FileExistsError or OSError."""
        written = self._model.save(path, overwrite=overwrite)
        self.path = self.save_path = Path(written)
        self.undo_stack.setClean()
        self.fileChanged.emit()
        self.saved.emit()
        return written

    # ------------------------------------------------------------------ recordings

    @contextmanager
    def rebuilding(self) -> Iterator[None]:
        """Rebuild the document from a recording (:func:`app.editor.persistence.recording.replay`):
        inside, :attr:`replaying` is True and no signal comes, so the state may be set directly;
        at the end views are told once that everything is new."""
        self.replaying = True
        try:
            with QSignalBlocker(self):
                yield
        finally:
            self.replaying = False
        for signal in (self.loaded, self.segmentChanged, self.levelChanged) if self.editable else (self.loaded,):
            signal.emit()
        self.fileChanged.emit()

    # ------------------------------------------------------------------ internals

    @property
    def _model(self) -> EditableModel:
        if self.model is None:
            raise RuntimeError("no structure is open")
        return self.model

    def _check_editable(self) -> None:
        """Raise RuntimeError without a structure, ValueError saying why for one only viewed."""
        if not self._model.ribbons:
            raise ValueError(self.read_only_reason)

    def _set_model(self, model: EditableModel, keep_view: bool = False) -> None:
        """Make ``model`` the document, at its longest segment (the first of them) and the default
        level (or, with ``keep_view``, at the segment and level shown, where the new model has them)."""
        segment, level = self.segment, self.level
        if self.model is None or model.structure is not self.model.structure:
            self.measurements.replace([])  # (their rows name other atoms)
        self.history.reset()
        self.model = model
        model.carry_ligands = self.carry_ligands
        self.paths = segment_paths(model.ribbons)
        self.ca_rows = ca_rows(model.structure)
        longest = int(np.argmax([len(s) for s in model.structure.segments])) if model.ribbons else 0
        self.segment = segment if keep_view and segment < len(model.ribbons) else longest
        self.level = min(level, self.max_level) if keep_view else float(max(0, round(self.max_level - LEVELS_BELOW_MAX)))
        self.pick = None
        self.selection = self.selected_groups = np.empty(0, dtype=np.int64)
        self._preview = None
        self._curves.clear()
        self.kept_view = keep_view
        self.loaded.emit()

    def _preview_edit(self, plan: Callable[[], Edit]) -> None:
        self._check_editable()
        previous = self._preview
        if previous is not None:
            self._model.revert(previous)
        edit = plan()
        if self.regularize_while_dragging:
            edit = regularized(self._model, edit)
        self._model.apply(edit)
        self._preview = edit
        if previous is None:
            self._edited(Change(edit.segment, edit.residues, edit.rows))
        else:  # what the last preview moved must be redrawn too
            n_residues, n_atoms = len(self.paths[edit.segment].residue_u), len(self._model.coords)
            self._edited(Change(edit.segment, _union(previous.residues, edit.residues, n_residues),
                                _union(previous.rows, edit.rows, n_atoms)))

    def _edited(self, change: Change) -> None:
        self._curves.pop(change.segment, None)
        self.changed.emit(change)

    def _level_changed(self) -> None:
        self._curves.clear()
        self._set_pick(None)
        self.levelChanged.emit()

    def _set_pick(self, pick: Pick | None) -> None:
        if pick is None and self.pick is None:
            return
        self.pick = pick
        self.picked.emit()


def _union(a: np.ndarray, b: np.ndarray, size: int) -> np.ndarray:
    """Sorted union of two index arrays into ``range(size)`` (a mask beats hashing here)."""
    mask = np.zeros(size, dtype=bool)
    mask[a] = True
    mask[b] = True
    return np.flatnonzero(mask)
