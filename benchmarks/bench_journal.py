"""Cost of journalling one undo step for crash recovery (goal: under 5 ms per step on 4YVS).

Usage: ``python benchmarks/bench_journal.py [STRUCTURE]`` (default: 4YVS, 3,405 residues).
Edits every segment at its top level, two levels below and at a fractional level, then
undoes and redoes; for each step it times the journal's work (encoding the records and
writing them to the operating system; the fsync runs later in a background thread) and
prints the bytes written, beside what rewriting the whole model per step would write.
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from PySide6.QtCore import QCoreApplication

from app.editor.document import Document
from app.editor.persistence.journal import Journal

DATA = Path(__file__).resolve().parent.parent / "tests" / "data"


class TimedJournal(Journal):
    """A journal that times each of its steps."""

    times: list[float]
    sizes: list[int]

    def _step(self) -> None:
        before = self.path.stat().st_size if self.path is not None else 0
        start = time.perf_counter()
        super()._step()
        elapsed = 1e3 * (time.perf_counter() - start)
        written = self.path.stat().st_size - before if self.path is not None else 0
        if written:  # a step reported twice (index and clean state changed) is written once
            self.times.append(elapsed)
            self.sizes.append(written)


def main() -> None:
    path = Path(sys.argv[1]) if len(sys.argv) > 1 else DATA / "4YVS.cif.gz"
    QCoreApplication.instance() or QCoreApplication([])
    document = Document()
    document.open(path)
    document.set_regularization(on_release=False)  # the edits themselves are not what is timed
    with tempfile.TemporaryDirectory() as folder:
        journal = TimedJournal(document, Path(folder))
        journal.times, journal.sizes = [], []
        rng = np.random.default_rng(1)
        rows = []
        for depth, label in ((0, "top level"), (2, "two levels below"), (2.5, "fractional, 2.5 below")):
            journal.times.clear(), journal.sizes.clear()
            for segment in range(len(document.model.ribbons)):
                document.set_segment(segment)
                document.set_level(document.max_level - depth)
                n = len(document.level_curve().control_points)
                document.preview_move(int(rng.integers(n)), rng.normal(size=3))
                document.finish_drag(f"bench {segment}")
            rows.append((f"push, {label}", list(journal.times[1:]), list(journal.sizes[1:])))  # the first: header
        journal.times.clear(), journal.sizes.clear()
        for _ in range(20):
            document.undo_stack.undo()
        for _ in range(20):
            document.undo_stack.redo()
        rows.append(("undo and redo", list(journal.times), list(journal.sizes)))
        journal.stop()
        journal.discard()
    model_bytes = document.model.coords.nbytes
    print(f"{path.name}: {document.structure.n_atoms} atoms, {len(document.model.ribbons)} segments; "
          f"rewriting the model per step would write {model_bytes / 1e3:.0f} kB")
    print(f"  {'step':<34}{'steps':>6}{'median ms':>11}{'max ms':>9}{'median kB':>11}")
    for label, times, sizes in rows:
        print(f"  {label:<34}{len(times):>6}{np.median(times):>11.2f}{max(times):>9.2f}"
              f"{np.median(sizes) / 1e3:>11.1f}")


if __name__ == "__main__":
    main()
