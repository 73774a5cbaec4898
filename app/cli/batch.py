"""Running one task over many structure files (``analyze``, ``index``): the files named and
the structure files in the folders named, run in this process, in worker processes of this
machine, or on a Dask cluster (a private local one, or a scheduler at an address).
"""

from __future__ import annotations

import argparse
import contextlib
import ctypes
import multiprocessing
import os
import signal
import socket
import struct
import sys
import urllib.parse
from collections.abc import Callable, Iterator
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path
from typing import TypeVar

from app.arguments import bounded
from app.errors import InputError

DASK_TIMEOUT = 10.0
"""Seconds to connect to a Dask scheduler and hear its greeting."""
DASK_FRAME = struct.Struct("<Q")
"""A Dask message starts with its length: 8 bytes, little-endian."""
DASK_GREETING_MAX = 1 << 20
"""Bytes a scheduler's greeting (its handshake) may take: a few hundred in practice."""
PR_SET_PDEATHSIG = 1
"""prctl(2): the signal a process gets when its parent ends."""
STRUCTURE_SUFFIXES = (".pdb", ".ent", ".cif", ".mmcif")
T = TypeVar("T")


def batch_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the files of a run over many structures and where it runs (:func:`run_tasks`):
    ``PATH...``, ``--jobs`` and ``--scheduler``."""
    parser.add_argument("paths", nargs="+", type=Path, metavar="PATH",
                        help="structure files or folders (searched recursively for .pdb/.ent/.cif/.mmcif, optionally .gz)")
    parser.add_argument("--jobs", type=bounded(int, 1, 4096), default=len(os.sched_getaffinity(0)), metavar="N",
                        help="worker processes (default: all cores)")
    parser.add_argument("--scheduler", nargs="?", const="local", metavar="ADDRESS",
                        help="run on a Dask cluster (e.g. tcp://host:8786); without ADDRESS, a local cluster "
                        "of --jobs workers (needs the 'cluster' extra: dask[distributed])")


def structure_paths(paths: list[Path]) -> list[Path]:
    """The files named, and the structure files inside the folders named (sorted, recursive)."""
    found: list[Path] = []
    for path in paths:
        if path.is_dir():
            found += sorted(
                p for p in path.rglob("*")
                if p.is_file() and not p.name.startswith(".")
                and p.name.lower().removesuffix(".gz").endswith(STRUCTURE_SUFFIXES)
            )
        else:
            found.append(path)  # a file that cannot be read is reported and skipped later
    if not found:
        raise InputError(f"no structure files (.pdb, .ent, .cif, .mmcif, optionally .gz) in {', '.join(map(str, paths))}")
    return found


def run_tasks(task: Callable[[Path], T], paths: list[Path], jobs: int, scheduler: str | None,
              failed: Callable[[Path, str], T]) -> Iterator[tuple[int, T]]:
    """(index, ``task(path)``) of every path, in order of completion: in this process
    (``jobs`` 1), in ``jobs`` worker processes, or on the Dask cluster at ``scheduler``
    ('local': a private one of ``jobs`` workers). ``task`` must pickle (a top-level function,
    or a partial of one); a worker that dies gives ``failed(path, reason)``."""
    if scheduler is not None:
        yield from _run_dask(task, paths, jobs, scheduler, failed)
    elif jobs == 1 or len(paths) == 1:
        for index, path in enumerate(paths):
            yield index, task(path)
    else:
        context = multiprocessing.get_context("spawn")  # no fork of a threaded parent; workers are its children
        with ProcessPoolExecutor(min(jobs, len(paths)), mp_context=context, initializer=_end_with_parent,
                                 initargs=(os.getpid(),)) as pool:
            futures = {pool.submit(task, path): index for index, path in enumerate(paths)}
            try:
                for future in as_completed(futures):
                    index = futures.pop(future)  # hold no finished result longer than needed
                    yield index, _outcome(future, paths[index], failed)
            except BaseException:  # Ctrl+C or an error: drop the files not started yet
                pool.shutdown(cancel_futures=True)
                raise


def _run_dask(task: Callable[[Path], T], paths: list[Path], jobs: int, address: str,
              failed: Callable[[Path, str], T]) -> Iterator[tuple[int, T]]:
    try:
        import dask
        from dask.distributed import Client, LocalCluster, as_completed as dask_completed
    except ImportError:
        raise InputError("--scheduler needs Dask: pip install 'dask[distributed]' (the 'cluster' extra)") from None
    with contextlib.ExitStack() as stack:
        try:
            if address == "local":
                client = _local_client(stack, LocalCluster, Client, jobs, dask)
            else:
                _check_scheduler(address)
                client = stack.enter_context(Client(address, timeout=DASK_TIMEOUT))
        except (OSError, ValueError, TimeoutError) as error:
            raise InputError(f"cannot reach the Dask scheduler {address}: {error}") from None
        futures = client.map(task, paths, pure=False)
        index = {future.key: k for k, future in enumerate(futures)}
        completed = dask_completed(futures)
        del futures  # a result is released on the cluster once it has been handled
        for future in completed:
            k = index.pop(future.key)
            yield k, _outcome(future, paths[k], failed)


def _local_client(stack: contextlib.ExitStack, local_cluster: type, client: type, jobs: int, dask: object) -> object:
    """A client of a cluster on this machine that only this process can use: TLS with a
    certificate made for this run (no other user can submit tasks to it), on 127.0.0.1,
    with the HTTP servers of the scheduler and the workers stopped."""
    try:
        from distributed.security import Security

        security = Security.temporary()
    except ImportError:
        raise InputError("--scheduler needs the 'cryptography' package for a private local cluster: "
                         "pip install 'ribbonwave[cluster]'") from None
    stack.enter_context(dask.config.set({"distributed.scheduler.http.routes": [],
                                         "distributed.worker.http.routes": []}))
    cluster = stack.enter_context(local_cluster(
        n_workers=jobs, threads_per_worker=1, processes=True, protocol="tls", security=security, host="127.0.0.1",
        dashboard_address=None, worker_dashboard_address=None))
    cluster.scheduler.http_server.stop()
    connected = stack.enter_context(client(cluster, security=security, timeout=DASK_TIMEOUT))
    connected.run(_stop_http_server)
    return connected


def _stop_http_server(dask_worker: object) -> None:
    """Run on each worker of the local cluster: no HTTP endpoint (metrics, health) on it."""
    dask_worker.http_server.stop()


def _check_scheduler(address: str) -> None:
    """Refuse an address that is not ``tcp://HOST:PORT``, and a server there that does not
    greet like a Dask scheduler within DASK_TIMEOUT (Dask would take any 8 bytes it sends
    for the length of a message, and allocate it)."""
    parts = urllib.parse.urlsplit(address if "://" in address else f"tcp://{address}")
    try:
        port = parts.port
    except ValueError:
        port = None
    if parts.scheme != "tcp" or not parts.hostname or port is None or parts.path not in ("", "/"):
        raise InputError(f"--scheduler {address}: expected tcp://HOST:PORT (a scheduler with TLS needs its "
                         "credentials, which analyze does not take)")
    try:
        with socket.create_connection((parts.hostname, port), timeout=DASK_TIMEOUT) as connection:
            connection.settimeout(DASK_TIMEOUT)
            greeting = b""
            while len(greeting) < DASK_FRAME.size:
                chunk = connection.recv(DASK_FRAME.size - len(greeting))
                if not chunk:
                    break
                greeting += chunk
    except TimeoutError:
        raise InputError(f"--scheduler {address}: the server there does not greet like a Dask scheduler "
                         f"(nothing within {DASK_TIMEOUT:g} s)") from None
    except OSError as error:
        raise InputError(f"cannot reach the Dask scheduler {address}: {error.strerror or error}") from None
    if len(greeting) < DASK_FRAME.size or not 0 < DASK_FRAME.unpack(greeting)[0] <= DASK_GREETING_MAX:
        raise InputError(f"--scheduler {address}: the server there is not a Dask scheduler")


def _end_with_parent(parent: int) -> None:
    """In a worker (Linux): be killed when ``analyze`` (process ``parent``, which started it)
    ends, so that killing ``analyze`` leaves no worker behind."""
    if sys.platform.startswith("linux"):
        ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGKILL)
        if os.getppid() != parent:  # it ended while this worker started
            os._exit(1)


def _outcome(future, path: Path, failed: Callable[[Path, str], T]) -> T:
    """A finished task's outcome; a worker that died gives ``failed``'s, not a failed run."""
    try:
        return future.result()
    except Exception as error:  # noqa: BLE001 - e.g. a worker killed while reading this file
        return failed(path, f"worker failed ({type(error).__name__}: {error})")
