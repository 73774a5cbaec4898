"""A document as records and back: the file as read, every undo step and the current state
(in the format of :mod:`app.editor.persistence.records`), for the crash-recovery journal and
session files."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from app.editor.document import Document
from app.editor.history import Base
from app.editor.persistence import records


def state(document: Document) -> dict:
    """The stack position, the clean position, the file names, level, segment and
    multiresolution switch of ``document`` (the fields of an ``index`` record)."""
    stack = document.undo_stack
    return {"index": stack.index(), "clean": stack.cleanIndex(),
            "path": str(document.path), "save_path": None if document.save_path is None else str(document.save_path),
            "level": document.level, "segment": document.segment, "multiresolution": document.multiresolution}


def recording(document: Document) -> list[records.Record]:
    """``document`` as records: the file as read, where the history starts (if its oldest steps
    were dropped), every undo step, the current state."""
    stack, start = document.undo_stack, document.history.base
    steps = [records.push(k, stack.text(k), stack.command(k).edits) for k in range(stack.count())]
    return [records.header(document.path, document.kind.value, document.source, document.model_number),
            *([] if start is None else [records.base(start)]), *steps, records.Record("index", state(document))]


def replay(document: Document, recording: list[records.Record]) -> list[str]:
    """Make ``document`` what ``recording`` (:func:`recording`, or a journal) describes: the
    file as read (the same model), the same undo history at the same position, bit for bit.
    Each step is checked before it is pushed (:meth:`~core.protein.model.EditableModel.check`):
    one that was not made on the document as replayed so far (a step before it lost, another
    structure) is left out, and so is every step built on it. Views are told once, at the end.
    Returns what was left out, for people; raises StructureError for an unreadable embedded file."""
    head, files, view, left_out = recording[0].fields, None, None, []
    with document.rebuilding():
        document.open(Path(head["path"]), head["kind"], records.source_of(recording[0]), records.model_of(head))
        stack = document.undo_stack
        for record in recording[1:]:
            if record.kind == "base":
                reason = "it comes after steps" if stack.count() else _unfit_base(document, records.base_of(record))
                if reason is None:
                    start = records.base_of(record)
                    document.model.reset_to(start.coords, start.points)
                    document.history.reset(start)
                else:
                    left_out.append(f"where the history starts: {reason}")
            elif record.kind == "push":
                reason = _unfit(document, record)
                if reason is None:
                    document.history.push(records.edits_of(record), record.fields["text"])
                else:
                    left_out.append(f"step {record.fields['at'] + 1} ({record.fields['text'][:60]}): {reason}")
            elif record.kind == "index":
                stack.setIndex(min(record.fields["index"], stack.count()))
                files = view = record.fields
            elif record.kind == "state":
                view = record.fields
        if files is not None:
            left_out += _past_the_steps(files, stack.count())
            _restore_files(document, files)
        if view is not None:
            document.segment = max(0, min(int(view["segment"]), len(document.model.ribbons) - 1))
            document.multiresolution = bool(view["multiresolution"])
            document.level = float(np.clip(view["level"], 0.0, document.max_level))
    return left_out


def _unfit_base(document: Document, start: Base) -> str | None:
    """Why ``start`` cannot be where the history of ``document`` starts (None: it can)."""
    model = document.model
    if start.coords.shape != model.coords.shape or [p.shape for p in start.points] != \
            [ribbon.points.shape for ribbon in model.ribbons]:
        return "its atoms or control points are not the structure's"
    return None


def _unfit(document: Document, record: records.Record) -> str | None:
    """Why the step of ``record`` cannot be pushed where it was (None: the stack is left at
    that position, the document as the step found it)."""
    stack, at = document.undo_stack, record.fields["at"]
    if at > stack.count():
        return "a step before it is missing"
    index = stack.index()
    stack.setIndex(at)
    model, applied, reason = document.model, [], None
    try:
        for edit in records.edits_of(record):  # (each edit of a step starts where the one before ended)
            model.check(edit)
            model.apply(edit)
            applied.append(edit)
    except ValueError as error:
        reason = str(error)
    for edit in reversed(applied):
        model.revert(edit)
    if reason is not None:
        stack.setIndex(index)
    return reason


def _past_the_steps(state: dict, count: int) -> list[str]:
    """What of the last ``index`` record's positions lies past the ``count`` steps restored."""
    return [f"the {what} position {state[name]} is past the {count} steps restored" for name, what in
            (("index", "current"), ("clean", "saved")) if state[name] > count]


def _restore_files(document: Document, state: dict) -> None:
    """The clean position and the structure's file name of an ``index`` record."""
    stack = document.undo_stack
    index = stack.index()
    if 0 <= state["clean"] <= stack.count():
        stack.setIndex(state["clean"])
        stack.setClean()
    else:
        stack.resetClean()
    stack.setIndex(index)
    document.path = Path(state["path"])
    document.save_path = None  # Save writes without asking only where Save As chose in this run: a session
    # (perhaps someone else's) or a journal never points it at a file ("save_path" is recorded for older readers)
