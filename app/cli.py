"""The ``ribbonwave`` command line.

``ribbonwave [FILE] [--screenshot OUT.png] [--level L]`` opens the editor window; it is the ``open``
command, used whenever the first argument is not the name of a command. Every command
is a :class:`Command` in :data:`COMMANDS`: a function that declares its arguments, a
handler, and one line of help. ``ribbonwave --help`` lists them all.
"""

import argparse
import os
import re
import signal
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import NamedTuple

from app import DEFAULT_STRUCTURE, analysis_commands, structure_commands, surface_commands, validate_commands
from app.structure_commands import InputError

PROG = "ribbonwave"
DEFAULT_COMMAND = "open"
VECTOR_OPTIONS = ("--move",)
"""Options whose value is a comma-separated vector that may start with a minus sign."""


class Command(NamedTuple):
    """A subcommand of ``ribbonwave``."""

    help: str
    add_arguments: Callable[[argparse.ArgumentParser], None]
    run: Callable[[argparse.Namespace], int]


def _open_arguments(parser: argparse.ArgumentParser) -> None:
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


def _open(args: argparse.Namespace) -> int:
    # Qt and VTK load only for the window, so commands without one start fast.
    from PySide6.QtWidgets import QApplication

    from app.document import Document
    from app.main_window import MainWindow
    from app.scene import Layer
    from core.structure import StructureError

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


COMMANDS: dict[str, Command] = {
    DEFAULT_COMMAND: Command("open a structure in the editor window (the default)", _open_arguments, _open),
    "info": Command("chains, segments, residues, secondary structure and levels of a structure",
                    structure_commands.info_arguments, structure_commands.run_info),
    "curve": Command("the residue points C^r of the ribbon at a level, one row per residue",
                     structure_commands.curve_arguments, structure_commands.run_curve),
    "edit": Command("move one control point (or residue curve point) at a level and save the model",
                    structure_commands.edit_arguments, structure_commands.run_edit),
    "analyze": Command("Cα–C^r deviations over many structures by decomposition step (Carson's Fig. 7)",
                       analysis_commands.analyze_arguments, analysis_commands.run_analyze),
    "compare": Command("superpose two chains and judge fits on fewer Cα or on low-resolution curves",
                       analysis_commands.compare_arguments, analysis_commands.run_compare),
    "surface": Command("molecular surface, globe, DNA cylinder, remeshing or density map at a level, to .vtp/.ply/.png",
                       surface_commands.surface_arguments, surface_commands.run_surface),
    "validate": Command("geometry report: peptide junctions, Ramachandran outliers, clashes",
                        validate_commands.validate_arguments, validate_commands.run_validate),
}


def build_parser() -> argparse.ArgumentParser:
    """Return the parser of all commands; ``main`` supplies the default command."""
    parser = argparse.ArgumentParser(
        prog=PROG,
        usage=f"{PROG} [FILE] [--screenshot OUT.png] [--level L]\n       {PROG} COMMAND [ARGS ...]",
        description="Multiresolution (wavelet) analysis and editing of protein structures. "
        f"Without a command, FILE opens in the editor window (the {DEFAULT_COMMAND!r} command).",
    )
    subparsers = parser.add_subparsers(title="commands", dest="command", metavar="COMMAND", required=True)
    for name, command in COMMANDS.items():
        subparser = subparsers.add_parser(name, prog=f"{PROG} {name}", help=command.help, description=command.help)
        command.add_arguments(subparser)
        subparser.set_defaults(run=command.run)
    return parser


def _attach_negative_vectors(args: list[str]) -> list[str]:
    """Write ``--move -3,4,0`` as ``--move=-3,4,0``: argparse takes '-3,4,0' for an option."""
    glued: list[str] = []
    for arg in args:
        if glued and glued[-1] in VECTOR_OPTIONS and re.fullmatch(r"-[0-9.][0-9.,eE+-]*", arg):
            glued[-1] = f"{glued[-1]}={arg}"
        else:
            glued.append(arg)
    return glued


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``ribbonwave`` with ``argv`` (default: ``sys.argv[1:]``) and return the exit status."""
    args_list = _attach_negative_vectors(list(sys.argv[1:] if argv is None else argv))
    if not args_list or (args_list[0] not in COMMANDS and args_list[0] not in ("-h", "--help")):
        args_list.insert(0, DEFAULT_COMMAND)
    args = build_parser().parse_args(args_list)
    try:
        return args.run(args)
    except InputError as error:
        print(f"{PROG}: error: {error}", file=sys.stderr)
        return 1
    except BrokenPipeError:  # output piped into a reader that stopped early (e.g. head)
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1
