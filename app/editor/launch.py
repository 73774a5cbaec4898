"""``ribbonwave [FILE]``: the editor window on a structure, from the command line.

The arguments are declared without Qt; Qt and VTK load only when the window opens, so the
headless commands start fast.
"""

from __future__ import annotations

import argparse
import importlib
import os
import signal
import sys
import threading
import traceback
from collections.abc import Callable
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, TypeVar

from app import DEFAULT_STRUCTURE, PROG
from app.arguments import IMAGE_SIDE, LEVEL, SUPERSAMPLING, bounded, chain_hint, file_and_chain, writable_output
from app.errors import InputError

if TYPE_CHECKING:
    from app.editor.main_window import MainWindow

T = TypeVar("T")

MAX_SCRIPT_BYTES = 16 * 2**20
MAX_MODEL = 100_000
"""Largest ``--model`` accepted before the file is read."""
WINDOWLESS_PLATFORMS = ("offscreen", "minimal", "minimalegl", "linuxfb", "vnc")
"""Qt platforms that cannot hold the OpenGL view of the editor."""


def open_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the arguments of the editor window (``ribbonwave [FILE] ...``)."""
    parser.add_argument(
        "file",
        nargs="?",
        type=Path,
        default=DEFAULT_STRUCTURE,
        metavar="FILE",
        help="structure file (PDB or mmCIF, optionally gzipped) or session (.rwsession); "
        "default: the bundled 1UBQ.pdb",
    )
    parser.add_argument(
        "--recover",
        action="store_true",
        help="restore the unsaved edits of the last editor that did not close cleanly (FILE is not read)",
    )
    parser.add_argument(
        "--script",
        type=Path,
        metavar="SCRIPT.py",
        help="run a Python script in the editor, with the object rw (see the README), after FILE is "
        "loaded; then exit (unsaved edits stay in the recovery journal)",
    )
    parser.add_argument(
        "--screenshot",
        type=Path,
        metavar="OUT.png",
        help="render the window to a PNG image and exit instead of running interactively",
    )
    parser.add_argument(
        "--export-image",
        type=Path,
        metavar="OUT.png",
        help="render the 3D view to a PNG image, as File > Export Image does, and exit",
    )
    parser.add_argument(
        "--width",
        type=bounded(int, *IMAGE_SIDE),
        metavar="W",
        help="--export-image width in pixels (default: by --height and the view's aspect ratio, or the view's)",
    )
    parser.add_argument(
        "--height",
        type=bounded(int, *IMAGE_SIDE),
        metavar="H",
        help="--export-image height in pixels (default: by --width and the view's aspect ratio, or the view's)",
    )
    parser.add_argument(
        "--supersample",
        type=int,
        choices=SUPERSAMPLING,
        metavar="N",
        help="--export-image as the mean of N x N renderings shifted within each pixel, smoothing edges: "
        f"{', '.join(map(str, SUPERSAMPLING))} (default 1)",
    )
    parser.add_argument(
        "--transparent",
        action="store_true",
        help="--export-image on a transparent background (alpha 0 behind the scene)",
    )
    parser.add_argument(
        "--overwrite",
        action="store_true",
        help="replace the --screenshot or --export-image image if it exists",
    )
    parser.add_argument(
        "--model",
        type=bounded(int, 1, MAX_MODEL),
        default=1,
        metavar="N",
        help="model of a multi-model entry (e.g. an NMR ensemble) to show and edit, counted from 1 (default 1)",
    )
    parser.add_argument(
        "--assembly",
        type=bounded(int, 1, MAX_MODEL),
        metavar="N",
        help="open biological assembly N of FILE (its REMARK 350 or _pdbx_struct_assembly records, counted "
        "from 1), built from --model: e.g. a virus capsid from its asymmetric unit",
    )
    parser.add_argument(
        "--level",
        type=bounded(float, *LEVEL),
        metavar="L",
        help="start at this level (0 .. log2 N; default: about two levels below full resolution)",
    )
    parser.add_argument(
        "--ribbon",
        choices=("peptide", "calpha"),
        default="peptide",
        help="peptide-plane ribbon (default) or the curve through the Cα atoms",
    )
    parser.add_argument(
        "--compare",
        nargs="+",
        default=[],
        metavar="FILE[:CHAIN]",
        help="structures to superpose on the edited chain and show at the same depth below their top level, "
        "each in its own colour (default chain: the longest)",
    )
    parser.add_argument(
        "--hide",
        nargs="+",
        default=[],
        metavar="LAYER",
        help="layers to start hidden, e.g. cartoon control-points (see the Display dock)",
    )


def run_open(args: argparse.Namespace) -> int:
    """Open the editor on what the arguments name; with ``--script``, ``--screenshot`` or
    ``--export-image``, do that and exit (the exit status), else run until the window closes."""
    if args.export_image is None:
        given = [f"--{name}" for name in ("width", "height", "supersample", "transparent")
                 if getattr(args, name) not in (None, False)]
        if given:
            raise InputError(f"{', '.join(given)}: only with --export-image (the 3D view; --screenshot takes the "
                             "whole window)")
    # Qt and VTK load only for the window, so commands without one start fast.
    from PySide6.QtWidgets import QApplication

    from app.editor import busy
    from app.editor.main_window import MainWindow
    from app.editor.sketch import read_trace

    if sys.platform.startswith("linux"):
        _check_display()
    script = _read_script(args.script) if args.script is not None else None
    images = [path for path in (args.screenshot, args.export_image) if path is not None]
    for path in images:
        writable_output(path, args.overwrite)
    from app.editor.persistence.folder import checked_folder, state_folder

    try:
        checked_folder(state_folder())  # (unsaved edits are journalled there, and restored from there)
    except OSError as error:
        raise InputError(str(error)) from None
    app = QApplication.instance() or QApplication(sys.argv[:1])
    unattended = script is not None or bool(images)
    window = MainWindow(furnish=unattended)
    try:
        if unattended:
            window.files.unattended = True
            _load(window, args)
        else:  # a person waits: the window at once, the editor as it loads, then the structure read and drawn
            window.show()
            with busy.opening(window, _opened_name(args)):
                # the file as stored is sketched, not restored edits or an assembly (nor a session: no atoms)
                if not args.recover and args.assembly is None:
                    trace = _meanwhile(partial(read_trace, args.file, args.model))
                    if trace is not None:
                        window.sketch(trace)
                _meanwhile(partial(importlib.import_module, "app.editor.window_parts"))
                if not window.isVisible():  # closed before anything was read
                    return 0
                window.furnish()
                with window.files.opening(_opened_name(args)):
                    _load(window, args)
    except InputError:
        window.close()
        raise
    window.show()
    if not window.files.unattended and not args.recover:
        window.sessions.offer_recovery()
    status = 0
    if script is not None:
        app.processEvents()  # the window laid out, as a person would first see it
        status = _run_script(window, args.script, script)
    if window.isVisible() and images:
        from app.editor.features.export import export_view

        app.processEvents()  # lay the window out before it is grabbed
        try:
            if args.screenshot is not None:
                window.export.save_screenshot(args.screenshot, overwrite=args.overwrite)
            if args.export_image is not None:
                export_view(window.plotter, args.export_image, args.width, args.height,
                            supersample=args.supersample or 1, transparent=args.transparent, overwrite=args.overwrite)
        except OSError as error:
            window.close()
            raise InputError(str(error)) from error
        except ValueError as error:  # a size the export refuses
            window.close()
            raise InputError(f"--export-image: {error}") from error
    if window.files.unattended:
        window.close()
        kept = window.journal.kept
        if kept is not None:
            print(f"{PROG}: unsaved edits are kept in {kept}; `{PROG} --recover` restores them", file=sys.stderr)
        return status
    signal.signal(signal.SIGINT, signal.SIG_DFL)  # let Ctrl+C in the terminal end the event loop
    return app.exec()


def _load(window: MainWindow, args: argparse.Namespace) -> None:
    """Open what the arguments name in ``window``: the most recent journal left by a crash,
    a session or a structure, then the level, hidden layers and compared structures."""
    from app.editor.persistence import journal, records
    from app.editor.persistence.session import SUFFIX as SESSION_SUFFIX
    from app.editor.persistence.session import SessionError
    from app.editor.scene.scene import Layer
    from core.protein.input_files import StructureError

    if args.recover:
        left, _ = journal.sweep(window.journal.folder)
        if not left:
            aside = sorted(path.name for path in window.journal.folder.glob(f"*{journal.SET_ASIDE}"))
            raise InputError(f"nothing to recover: no journal of an editor that did not close cleanly in "
                             f"{window.journal.folder}" + (f" (kept there, unreadable here: {', '.join(aside)})"
                                                            if aside else ""))
        try:
            print(f"{PROG}: {window.sessions.restore_journal(left[0])}", file=sys.stderr)
        except (OSError, records.RecordError, StructureError) as error:
            raise InputError(f"{left[0]}: cannot restore ({error})") from error
    elif args.file.name.endswith(SESSION_SUFFIX):
        if args.assembly is not None:
            raise InputError("--assembly: a session opens as it was saved; give a structure file")
        try:
            window.sessions.open_session(args.file, raise_errors=True)
        except SessionError as error:
            raise InputError(str(error)) from error
    else:
        try:
            window.document.open(args.file, args.ribbon, model=args.model, assembly=args.assembly)
        except StructureError as error:
            raise InputError(str(error) + chain_hint(args.file)) from error
        if args.file != DEFAULT_STRUCTURE:
            window.files.add_recent(args.file)
    if args.level is not None:
        try:
            window.document.set_level(args.level)
        except ValueError as error:  # a structure only viewed has no level
            raise InputError(f"--level: {error}") from error
    for name in args.hide:
        layer = Layer.__members__.get(name.upper().replace("-", "_"))
        if layer is None:
            names = ", ".join(member.lower().replace("_", "-") for member in Layer.__members__)
            raise InputError(f"--hide: no layer {name!r}; layers: {names}")
        window.display_panel.layer_boxes[layer].setChecked(False)
    for spec in args.compare:
        path, chain = file_and_chain(spec)
        try:
            window.comparison.add(path, chain)
        except (StructureError, ValueError) as error:
            raise InputError(f"--compare {spec}: {error}") from error
    if args.compare:
        window.comparison_panel.parentWidget().raise_()  # the dock listing them in front of its tab group


def _meanwhile(work: Callable[[], T]) -> T:
    """``work()`` done in a thread while the event loop runs here: the window shown meanwhile is
    painted (its busy bar moves) and can be moved or closed."""
    from PySide6.QtCore import QEventLoop
    from PySide6.QtWidgets import QApplication

    done, outcome, failed = threading.Event(), [], []

    def run() -> None:
        try:
            outcome.append(work())
        except BaseException as error:  # noqa: BLE001 (raised again in the waiting thread)
            failed.append(error)
        finally:
            done.set()

    threading.Thread(target=run, name="meanwhile", daemon=True).start()
    while not done.wait(0.01):  # (waiting releases the interpreter to the work)
        QApplication.processEvents(QEventLoop.ProcessEventsFlag.ExcludeUserInputEvents)
    if failed:
        raise failed[0]
    return outcome[0]


def _opened_name(args: argparse.Namespace) -> Path:
    """What the arguments open, as its name is shown while it is read."""
    if args.recover:
        return Path("the unsaved edits")
    if args.assembly is None:
        return args.file
    from core.protein.assembly import assembly_path

    return assembly_path(args.file, args.assembly)


def _check_display() -> None:
    """Say what is wrong before Qt would abort: no display, a platform plugin Qt lacks or one
    without OpenGL windows, or an X display that does not answer."""
    import ctypes
    import ctypes.util

    import PySide6

    platform = os.environ.get("QT_QPA_PLATFORM", "").split(":")[0]
    if not platform and not any(map(os.environ.get, ("DISPLAY", "WAYLAND_DISPLAY"))):
        raise InputError("no display to open a window on; run under xvfb-run (scripts/ribbonwave.sh does)")
    if platform:
        plugins = Path(PySide6.__file__).parent / "Qt" / "plugins" / "platforms"
        known = sorted(p.name.removeprefix("libq").removesuffix(".so") for p in plugins.glob("libq*.so"))
        if known and platform not in known:
            raise InputError(f"QT_QPA_PLATFORM={platform!r} is not a Qt platform here; known: {', '.join(known)}")
        if platform in WINDOWLESS_PLATFORMS:
            raise InputError(f"QT_QPA_PLATFORM={platform!r} cannot show the 3D view (no OpenGL windows); "
                             "unset it, or run under xvfb-run")
    if platform in ("", "xcb") and os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY"):
        name = ctypes.util.find_library("X11")
        if name is not None:
            xlib = ctypes.CDLL(name)
            xlib.XOpenDisplay.restype = ctypes.c_void_p
            xlib.XOpenDisplay.argtypes = [ctypes.c_char_p]
            handle = xlib.XOpenDisplay(os.environ["DISPLAY"].encode())
            if not handle:
                raise InputError(f"cannot open the display DISPLAY={os.environ['DISPLAY']!r}: no X server "
                                 "answers there (or it refuses this user); run under xvfb-run")
            xlib.XCloseDisplay.argtypes = [ctypes.c_void_p]
            xlib.XCloseDisplay(handle)


def _read_script(path: Path) -> str:
    if path.exists() and not path.is_file():
        raise InputError(f"--script {path}: not a regular file")
    if path.is_file() and path.stat().st_size > MAX_SCRIPT_BYTES:
        raise InputError(f"--script {path}: more than {MAX_SCRIPT_BYTES // 2**20} MiB: not a script")
    try:
        return path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as error:
        raise InputError(f"--script {path}: cannot read ({getattr(error, 'strerror', None) or error})") from None


def _run_script(window: MainWindow, path: Path, text: str) -> int:
    """Run ``text`` (the script at ``path``) with ``rw``; an exception prints the script's
    traceback and gives exit status 1, ``sys.exit(n)`` gives ``n`` (0 to 255; any other number
    1, not what the operating system would keep of it: 256 would read as success), and
    ``sys.exit(message)`` prints the message and gives 1, as Python does."""
    namespace = {"__name__": "__main__", "__file__": str(path), "rw": window.rw}
    try:
        exec(compile(text, str(path), "exec"), namespace)  # noqa: S102 (running the user's script is the point)
    except SystemExit as error:
        if error.code is None:
            return 0
        if isinstance(error.code, int):
            return error.code if 0 <= error.code <= 255 else 1
        print(error.code, file=sys.stderr)
        return 1
    except BaseException as error:  # noqa: BLE001 (any failure of the script is reported, not raised)
        tb = error.__traceback__
        while tb is not None and tb.tb_frame.f_code.co_filename != str(path):
            tb = tb.tb_next  # from the script's own frames on
        traceback.print_exception(type(error), error, tb)
        return 1
    return 0
