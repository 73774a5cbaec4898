"""``ribbonwave [FILE]``: the editor window on a structure, from the command line.

The arguments are declared without Qt; Qt and VTK load only when the window opens, so the
headless commands start fast.
"""

import argparse
import os
import signal
import sys
from pathlib import Path

from app import DEFAULT_STRUCTURE
from app.errors import InputError
from core.protein.structure import StructureError


def open_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "file",
        nargs="?",
        type=Path,
        default=DEFAULT_STRUCTURE,
        metavar="FILE",
        help="structure file (PDB or mmCIF, optionally gzipped); default: the bundled 1UBQ.pdb",
    )
    parser.add_argument(
        "--screenshot",
        type=Path,
        metavar="OUT.png",
        help="render the window to a PNG image and exit instead of running interactively",
    )
    parser.add_argument(
        "--level",
        type=float,
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
        help="layers to start hidden, e.g. tube control-points (see the Display dock)",
    )


def run_open(args: argparse.Namespace) -> int:
    # Qt and VTK load only for the window, so commands without one start fast.
    from PySide6.QtWidgets import QApplication

    from app.editor.document import Document
    from app.editor.main_window import MainWindow
    from app.editor.scene.scene import Layer

    if args.level is not None and not args.level >= 0:
        raise InputError(f"--level must be >= 0; got {args.level:g}")
    if sys.platform.startswith("linux") and not any(map(os.environ.get, ("DISPLAY", "WAYLAND_DISPLAY",
                                                                         "QT_QPA_PLATFORM"))):
        raise InputError("no display to open a window on; run under xvfb-run (scripts/ribbonwave.sh does)")
    app = QApplication.instance() or QApplication(sys.argv[:1])
    document = Document()
    try:
        document.open(args.file, args.ribbon)
    except StructureError as error:
        raise InputError(str(error)) from error
    if args.level is not None:
        document.set_level(args.level)
    window = MainWindow(document)
    for name in args.hide:
        layer = Layer.__members__.get(name.upper().replace("-", "_"))
        if layer is None:
            window.close()
            names = ", ".join(member.lower().replace("_", "-") for member in Layer.__members__)
            raise InputError(f"--hide: no layer {name!r}; layers: {names}")
        window.display_panel.layer_boxes[layer].setChecked(False)
    for spec in args.compare:
        path, chain = _file_and_chain(spec)
        try:
            window.comparison.add(path, chain)
        except (StructureError, ValueError) as error:
            window.close()
            raise InputError(f"--compare {spec}: {error}") from error
    if args.compare:
        window.comparison_panel.parentWidget().raise_()  # the dock listing them in front of its tab group
    window.show()
    if args.screenshot is None:
        signal.signal(signal.SIGINT, signal.SIG_DFL)  # let Ctrl+C in the terminal end the event loop
        return app.exec()
    app.processEvents()  # lay the window out before it is grabbed
    try:
        window.save_screenshot(args.screenshot)
    except OSError as error:
        raise InputError(str(error)) from error
    finally:
        window.close()
    return 0


def _file_and_chain(spec: str) -> tuple[Path, str | None]:
    """``FILE`` or ``FILE:CHAIN`` (a chain only when ``FILE`` itself does not exist)."""
    path = Path(spec)
    if not path.exists() and ":" in spec:
        name, chain = spec.rsplit(":", 1)
        if chain and Path(name).exists():
            return Path(name), chain
    return path, None
