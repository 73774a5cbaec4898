"""Surfaces built in a process of their own: as fast in the editor as on the command line,
and stopped at once when they are no longer wanted.

A build in a thread of the editor shared the interpreter lock with the GUI thread: while the
view turned, each held the other up (a 4YVS globe took 27 s instead of 10, and the view drew
10 frames a second), and a running thread cannot be stopped (closing the window waited 9 s
for it). A :class:`SurfaceBuild` runs :func:`core.surfaces.levelled.build_surface` in a child
of a fork server that imported the surface modules once (:func:`start_server`), so a build
starts in milliseconds. The child runs at a lower priority (nice 10): where the view's frames
need the cores too (software OpenGL), they come first and the build takes what is left. It
sends the name of each stage as it starts, then the surface or the error that says why there
is none, through a pipe; closing the build kills the child, whatever it is doing. No Qt here:
the surface layer watches :meth:`SurfaceBuild.fileno` with a socket notifier.

The child imports the main module again, as every process started by :mod:`multiprocessing`
does (``ribbonwave`` and ``python -m app`` import almost nothing): a script that opens the
editor should keep its top level light and its work under ``if __name__ == "__main__"``.
"""

from __future__ import annotations

import multiprocessing
import os
from multiprocessing import forkserver
from multiprocessing.connection import Connection
from typing import TYPE_CHECKING

from core.protein.structure import AtomTable

if TYPE_CHECKING:
    from core.surfaces.levelled import LevelledSurface

SURFACE_CODE = "core.surfaces.levelled"
"""The module of the builds, imported by the fork server and every build, never by the editor."""

_FORKSERVER = "forkserver" in multiprocessing.get_all_start_methods()
_CONTEXT = multiprocessing.get_context("forkserver" if _FORKSERVER else "spawn")
"""Never a fork of the editor itself, whose Qt and OpenGL threads a child would inherit in an
unknown state. Where there is no fork server (Windows), each build starts a new interpreter."""

NICE = 10
"""How much lower the priority of a build is than the editor's."""


def start_server() -> None:
    """Start the fork server, which imports the surface modules in the background (a second or
    two) once, so that builds start at once; it ends with this process."""
    if _FORKSERVER:
        forkserver.set_forkserver_preload([SURFACE_CODE])
        forkserver.ensure_running()


class SurfaceBuild:
    """``build_surface(kind, atoms)`` running in a process of its own."""

    def __init__(self, kind: str, atoms: AtomTable) -> None:
        self.kind = kind
        self._receiver, sender = _CONTEXT.Pipe(duplex=False)
        self._process = _CONTEXT.Process(target=_build, args=(sender, kind, atoms), name=f"surface-{kind}",
                                         daemon=True)
        self._process.start()
        sender.close()  # the child holds the only writing end: the pipe closes when it ends

    def fileno(self) -> int:
        """The pipe's file descriptor: readable when a message waits, or when the child ended."""
        return self._receiver.fileno()

    def receive(self) -> str | LevelledSurface | Exception:
        """The next message (call when :meth:`fileno` is readable): the name of a stage, then
        the surface, or the ValueError or MemoryError that stopped it, or a ChildProcessError
        when the child ended without a word (killed, or a bug whose traceback it printed)."""
        try:
            return self._receiver.recv()
        except EOFError:
            self._process.join()
            return ChildProcessError(f"the build stopped (exit code {self._process.exitcode})")

    def close(self) -> None:
        """Kill the child if it still runs (at once, whatever it is doing) and close the pipe."""
        self._process.kill()
        self._process.join()
        self._receiver.close()


def _build(connection: Connection, kind: str, atoms: AtomTable) -> None:
    """In the child: send the name of each stage, then the surface or the error that stopped it."""
    from core.surfaces.levelled import build_surface

    if hasattr(os, "nice"):
        os.nice(NICE)
    try:
        result = build_surface(kind, atoms, progress=connection.send)
    except (ValueError, MemoryError) as error:
        result = error
    connection.send(result)
