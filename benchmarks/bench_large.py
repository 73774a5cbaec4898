"""Large structures and assemblies, the editor and PyMOL side by side: memory, first frame, rotation.

Usage: ``xvfb-run -a -s "-screen 0 1600x1000x24" python benchmarks/bench_large.py STRUCTURE ... [--assembly N]
[--frames N] [--viewport W H] [--no-pymol]`` (e.g. 2BUK.pdb.gz and 1RB8.pdb.gz of the shared set with
``--assembly 1``: their capsids of 95,280 and 306,720 atoms). For each structure a fresh editor process opens
it as ``ribbonwave STRUCTURE --assembly N`` does, with its 3D view resized to the viewport (PyMOL's 640 x 514 by
default), and reports the seconds from the process start to its first frame, its peak resident memory (VmHWM)
then, and the milliseconds per frame while the view turns: a mouse move with the left button held (QTest, as
``bench_interaction.py`` sends it: the frame in motion, with less detail) and the same view at rest, in full
detail. PyMOL (``benchmarks/pymol_peer.py``: its own GUI in a fresh process, the same viewport, its default
cartoon) is measured the same way in the same run: its first frame, peak memory, and frames turned by
``cmd.turn`` and drawn at once. Medians over the frames; memory in MiB, and the editor's over PyMOL's. One
untimed start of each on 1UBQ first compiles the bytecode.
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

import pymol_peer

ROOT = Path(__file__).resolve().parent.parent
CHILD = """
import json, statistics, sys, time
started, path, assembly, frames, width, height = (float(sys.argv[1]), sys.argv[2], int(sys.argv[3]), int(sys.argv[4]),
                                                  int(sys.argv[5]), int(sys.argv[6]))
from PySide6.QtCore import QPoint
from PySide6.QtTest import QTest
from PySide6.QtWidgets import QApplication
from PySide6.QtCore import Qt
app = QApplication([])
from app.editor.main_window import MainWindow
window = MainWindow()
window.document.open(path, assembly=assembly or None)
window.show()
QTest.qWaitForWindowExposed(window)
view = window.plotter
window.resize(window.width() + width - view.width(), window.height() + height - view.height())
while view.frames == 0:
    app.processEvents()
first = time.time() - started
memory = next(int(line.split()[1]) for line in open("/proc/self/status") if line.startswith("VmHWM")) / 1024

def timed(send):
    drawn = view.frames
    start = time.perf_counter()
    send()
    for _ in range(3):
        app.processEvents()
    assert view.frames > drawn, "no frame drawn"
    return time.perf_counter() - start

corner = QPoint(12, view.height() - 12)  # nothing there: the press turns the camera
QTest.mousePress(view, Qt.MouseButton.LeftButton, pos=corner)
moving, rest = [], []
for m in range(1, frames + 1):
    moving.append(timed(lambda m=m: QTest.mouseMove(view, corner + QPoint(3 * m, -2 * m))))
    rest.append(timed(window.scene.still))
QTest.mouseRelease(view, Qt.MouseButton.LeftButton, pos=corner + QPoint(3 * frames, -2 * frames))
memory = next(int(line.split()[1]) for line in open("/proc/self/status") if line.startswith("VmHWM")) / 1024
print("EDITOR " + json.dumps({"first frame": first, "memory": memory, "moving": statistics.median(moving),
                              "rest": statistics.median(rest), "atoms": window.document.structure.n_atoms,
                              "view": [view.width(), view.height()]}))
window.quit_unattended(discard=True)
"""


def editor(path: Path, env: dict[str, str], assembly: int | None, frames: int,
           viewport: tuple[int, int]) -> dict[str, float]:
    """One fresh editor process on ``path`` (its ``assembly``): first frame (s), peak memory (MiB) and
    median seconds per frame turning, in motion and at rest."""
    started = time.time()
    result = subprocess.run([sys.executable, "-c", CHILD, repr(started), str(path), str(assembly or 0), str(frames),
                             *map(str, viewport)], cwd=ROOT, capture_output=True, text=True,
                            env=dict(env, PYTHONPATH=str(ROOT)), timeout=1200, check=False)
    lines = [line for line in result.stdout.splitlines() if line.startswith("EDITOR ")]
    if result.returncode != 0 or not lines:
        raise RuntimeError(f"the editor on {path} failed (exit {result.returncode}):\n{result.stderr[-2000:]}")
    return json.loads(lines[-1][len("EDITOR "):])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("structures", nargs="+", type=Path)
    parser.add_argument("--assembly", type=int, help="biological assembly to open (e.g. 1)")
    parser.add_argument("--frames", type=int, default=20)
    parser.add_argument("--viewport", type=int, nargs=2, default=(640, 514), metavar=("W", "H"))
    parser.add_argument("--no-pymol", action="store_true", help="the editor alone")
    args = parser.parse_args()
    viewport = (args.viewport[0], args.viewport[1])
    print(f"{'structure':<22} {'program':<11} {'atoms':>9} {'first frame s':>14} {'peak MiB':>9} "
          f"{'turning ms':>11} {'at rest ms':>11} {'memory ratio':>13}")
    with tempfile.TemporaryDirectory() as folder:
        env = dict(os.environ, XDG_STATE_HOME=folder, XDG_CONFIG_HOME=folder, HOME=folder)  # not the user's settings
        env.pop("PYTHONDONTWRITEBYTECODE", None)
        env["PYTHONPYCACHEPREFIX"] = str(Path(folder) / "bytecode")
        warm = ROOT / "tests" / "data" / "1UBQ.pdb.gz"  # compiles the bytecode and fills font caches: not timed
        editor(warm, env, None, 1, viewport)
        if not args.no_pymol:
            pymol_peer.measure(sys.executable, warm, env)
        for path in args.structures:
            name = path.name.split(".")[0] + (f" assembly {args.assembly}" if args.assembly else "")
            ours = editor(path, env, args.assembly, args.frames, viewport)
            print(f"{name:<22} {'ribbonwave':<11} {ours['atoms']:>9,} {ours['first frame']:>14.2f} "
                  f"{ours['memory']:>9.0f} {1e3 * ours['moving']:>11.0f} {1e3 * ours['rest']:>11.0f}", flush=True)
            if args.no_pymol:
                continue
            peer = pymol_peer.measure(sys.executable, path, env, None if args.assembly is None else str(args.assembly),
                                      args.frames, viewport)
            atoms = peer["atoms"] * peer["states"]
            print(f"{name:<22} {'PyMOL':<11} {atoms:>9,} {peer['total']:>14.2f} {peer['memory']:>9.0f} "
                  f"{1e3 * peer['frame']:>11.0f} {1e3 * peer['frame']:>11.0f} "
                  f"{ours['memory'] / peer['memory']:>13.2f}", flush=True)


if __name__ == "__main__":
    main()
