"""The ``ribbonwave`` command line: the editor window or one of the headless commands.

``ribbonwave [FILE] [--screenshot OUT.png] [--level L]`` opens the editor window; it is the ``open``
command, used whenever the first argument is not the name of a command. Every command
is a :class:`Command` in :data:`COMMANDS`: one line of help and the module that declares its
arguments (``NAME_arguments``) and runs it (``run_NAME``). Only the module of the command
given is imported, so a headless command loads neither Qt nor the other commands.
``ribbonwave --help`` lists them all.
"""

import argparse
import importlib
import os
import re
import sys
from collections.abc import Sequence
from typing import NamedTuple

from app import PROG
from app.errors import InputError, printable

DEFAULT_COMMAND = "open"
VECTOR_OPTIONS = ("--move", "--core")
"""Options whose value may start with a minus sign: a comma-separated vector, or residue
ranges such as ``-45--30``."""


class Command(NamedTuple):
    """A subcommand of ``ribbonwave``: its help line and the module that implements it."""

    help: str
    module: str

    def add_arguments(self, name: str, parser: argparse.ArgumentParser) -> None:
        """Declare the arguments of command ``name`` on ``parser`` and make it run the command."""
        module = importlib.import_module(self.module)
        getattr(module, f"{name}_arguments")(parser)
        parser.set_defaults(run=getattr(module, f"run_{name}"))


COMMANDS: dict[str, Command] = {
    DEFAULT_COMMAND: Command("open a structure in the editor window (the default)", "app.editor.launch"),
    "info": Command("chains, segments, residues, secondary structure and levels of a structure", "app.cli.structure"),
    "curve": Command("the residue points C^r of the ribbon at a level, one row per residue", "app.cli.curve"),
    "edit": Command("move one control point (or residue curve point) at a level and save the model", "app.cli.edit"),
    "analyze": Command("Cα–C^r deviations over many structures by decomposition step (Carson's Fig. 7)",
                       "app.cli.analysis"),
    "compare": Command("superpose two chains and judge fits on fewer Cα or on low-resolution curves",
                       "app.cli.compare"),
    "index": Command("descriptors of the low-level curves of every protein chain of many structures, for search",
                     "app.cli.search"),
    "search": Command("the chains of an index of the fold nearest a query's, aligned by structure", "app.cli.search"),
    "surface": Command("molecular surface, globe, DNA cylinder, remeshing or density map at a level, to .vtp/.ply/.png",
                       "app.cli.surface"),
    "fit": Command("move a model onto another conformation, coarse to fine over the levels", "app.cli.fit"),
    "morph": Command("a multi-model movie from one conformation to another, the coarse motion first", "app.cli.fit"),
    "validate": Command("geometry report: peptide junctions, Ramachandran outliers, clashes", "app.cli.validate"),
    "contacts": Command("the hydrogen bonds and metal bonds of a ligand, residues or a chain", "app.cli.contacts"),
}


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """Return the parser of all commands, with the arguments of ``command`` (the one to run)
    declared; ``main`` supplies the default command."""
    parser = argparse.ArgumentParser(
        prog=PROG,
        usage=f"{PROG} [FILE] [--screenshot OUT.png] [--level L]\n       {PROG} COMMAND [ARGS ...]",
        description="Multiresolution (wavelet) analysis and editing of protein structures. "
        f"Without a command, FILE opens in the editor window (the {DEFAULT_COMMAND!r} command).",
    )
    subparsers = parser.add_subparsers(title="commands", dest="command", metavar="COMMAND", required=True)
    for name, spec in COMMANDS.items():
        subparser = subparsers.add_parser(name, prog=f"{PROG} {name}", help=spec.help, description=spec.help)
        if name == command:
            spec.add_arguments(name, subparser)
    return parser


def _attach_negative_vectors(args: list[str]) -> list[str]:
    """Write ``--move -3,4,0`` as ``--move=-3,4,0``: argparse takes '-3,4,0' for an option."""
    glued: list[str] = []
    for arg in args:
        if glued and glued[-1] in VECTOR_OPTIONS and re.fullmatch(r"-[0-9.][0-9A-Za-z.,+-]*", arg):
            glued[-1] = f"{glued[-1]}={arg}"
        else:
            glued.append(arg)
    return glued


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``ribbonwave`` with ``argv`` (default: ``sys.argv[1:]``) and return the exit status."""
    args_list = _attach_negative_vectors(list(sys.argv[1:] if argv is None else argv))
    if not args_list or (args_list[0] not in COMMANDS and args_list[0] not in ("-h", "--help")):
        args_list.insert(0, DEFAULT_COMMAND)
    args = build_parser(args_list[0]).parse_args(args_list)
    try:
        return args.run(args)
    except InputError as error:
        print(f"{PROG}: error: {printable(str(error))}", file=sys.stderr)
        return 1
    except BrokenPipeError:  # output piped into a reader that stopped early (e.g. head)
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1
