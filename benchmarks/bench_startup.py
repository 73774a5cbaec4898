"""Start-up: from a fresh interpreter to the editor's window on screen with a structure drawn.

Usage: ``xvfb-run -a python benchmarks/bench_startup.py [STRUCTURE] [--runs N]`` (default
1UBQ). Each run starts a new Python process that imports the editor, opens the structure,
shows the window and waits for its first frame; it prints the time spent importing, reading
and drawing, and the total since the process started. Medians over the runs.
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

DATA = Path(__file__).resolve().parent.parent / "tests" / "data"
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
                  "first frame": t3 - t2, "total": t3 - started}))
window.quit_unattended(discard=True)
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("structure", nargs="?", default="1UBQ.pdb.gz")
    parser.add_argument("--runs", type=int, default=5)
    args = parser.parse_args()
    path = Path(args.structure) if Path(args.structure).exists() else DATA / args.structure
    folder = tempfile.mkdtemp()
    env = dict(os.environ, XDG_STATE_HOME=folder, XDG_CONFIG_HOME=folder, HOME=folder)  # not the user's settings
    runs = []
    for _ in range(args.runs):
        started = time.time()
        result = subprocess.run([sys.executable, "-c", CHILD, str(path), repr(started)], capture_output=True,
                                text=True, env=env, check=True)
        runs.append(json.loads(result.stdout.strip().splitlines()[-1]))
    print(f"{path.name}: start-up to the first frame, medians of {args.runs} runs (s)")
    for key in runs[0]:
        print(f"  {key:<15} {np.median([run[key] for run in runs]):6.2f}")


if __name__ == "__main__":
    main()
