"""Start-up: from a fresh interpreter to the editor's window on screen with a structure drawn.

Usage: ``xvfb-run -a python benchmarks/bench_startup.py [STRUCTURE] [--runs N] [--against TREE]``
(default 1UBQ). Each run starts a new Python process that imports the editor, opens the
structure, shows the window and waits for its first frame; it prints the time spent
importing, reading and drawing, the total since the process started, and the processor time
the process used: medians over the runs, after one untimed start that compiles the bytecode.
``--against TREE`` (another checkout of ribbonwave, e.g. a ``git worktree add`` of an earlier
commit) times that tree's editor too, its runs taking turns with this tree's (each tree
first every other turn) so that both see the same load, and prints both columns and their
ratio.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT / "tests" / "data"
CHILD = """
import json, sys, time
started = float(sys.argv[2])
t0 = time.time()
from PySide6.QtWidgets import QApplication
app = QApplication([])
from app.editor.document import Document
from app.editor.main_window import MainWindow
t1 = time.time()
document = Document()
document.open(sys.argv[1])
window = MainWindow(document)
t2 = time.time()
window.show()
while window.plotter.frames == 0:
    app.processEvents()
t3 = time.time()
print(json.dumps({"interpreter": t0 - started, "imports": t1 - t0, "read and build": t2 - t1,
                  "first frame": t3 - t2, "total": t3 - started, "cpu": time.process_time()}))
window.quit_unattended(discard=True)
"""


def run(tree: Path, path: Path, env: dict[str, str]) -> dict[str, float]:
    """One start-up of the editor of ``tree`` (its own ``app`` and ``core``) on ``path``: seconds per phase."""
    started = time.time()
    result = subprocess.run([sys.executable, "-c", CHILD, str(path), repr(started)], cwd=tree, capture_output=True,
                            text=True, env=dict(env, PYTHONPATH=str(tree)), check=True)
    return json.loads(result.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("structure", nargs="?", default="1UBQ.pdb.gz")
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--against", type=Path, metavar="TREE",
                        help="another ribbonwave checkout to time side by side (e.g. the previous commit)")
    args = parser.parse_args()
    if args.runs < 1:
        parser.error(f"--runs must be at least 1; got {args.runs}")
    path = (Path(args.structure) if Path(args.structure).exists() else DATA / args.structure).resolve()
    trees = [ROOT] if args.against is None else [ROOT, args.against.resolve()]
    if not all((tree / "app" / "editor" / "main_window.py").is_file() for tree in trees):
        parser.error(f"--against {args.against}: not a ribbonwave checkout (no app/editor/main_window.py)")
    runs: list[list[dict[str, float]]] = [[] for _ in trees]
    with tempfile.TemporaryDirectory() as folder:
        env = dict(os.environ, XDG_STATE_HOME=folder, XDG_CONFIG_HOME=folder, HOME=folder)  # not the user's settings
        # bytecode cached, as after a first start, whatever this shell says (in the temporary folder: trees stay clean)
        env.pop("PYTHONDONTWRITEBYTECODE", None)
        env["PYTHONPYCACHEPREFIX"] = str(Path(folder) / "bytecode")
        for tree in trees:
            run(tree, path, env)  # compiles the bytecode and fills matplotlib's font cache: not timed
        for turn in range(args.runs):
            for times, tree in list(zip(runs, trees))[:: 1 if turn % 2 == 0 else -1]:  # who goes first alternates
                times.append(run(tree, path, env))
    rows = {key: [float(np.median([t[key] for t in times])) for times in runs] for key in runs[0][0]}
    print(f"{path.name}: start-up to the first frame, medians of {args.runs} runs (s)")
    if args.against is not None:
        print(f"  {'':<15} {'this':>6} {'against':>8} {'ratio':>6}    against: {trees[1]}")
    for key, values in rows.items():
        ratio = f" {values[0] / values[1]:6.2f}" if len(values) == 2 and values[1] else ""
        print(f"  {key:<15} {values[0]:6.2f}" + "".join(f" {value:8.2f}" for value in values[1:]) + ratio)


if __name__ == "__main__":
    main()
