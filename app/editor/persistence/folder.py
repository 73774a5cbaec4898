"""Where the recovery journals live, and the checks that make it safe to restore from there
(the standard library alone: the editor checks it before anything else loads)."""

from __future__ import annotations

import os
from pathlib import Path


def state_folder() -> Path:
    """Where journals live: ``$XDG_STATE_HOME/ribbonwave`` (default ``~/.local/state/ribbonwave``)."""
    base = os.environ.get("XDG_STATE_HOME") or str(Path.home() / ".local" / "state")
    return Path(base) / "ribbonwave"


def checked_folder(folder: Path) -> Path:
    """``folder``, made private (mode 0700) if missing; raises PermissionError unless it is the
    user's own and no one else may write in it (a journal there is restored as the user's work)."""
    folder.mkdir(mode=0o700, parents=True, exist_ok=True)
    info = folder.stat()
    if info.st_uid != os.getuid():
        raise PermissionError(f"the folder of recovery journals {folder} belongs to another user (uid {info.st_uid}); "
                              "set XDG_STATE_HOME to a folder of your own")
    if info.st_mode & 0o022:
        raise PermissionError(f"the folder of recovery journals {folder} may be written by other users (mode "
                              f"{info.st_mode & 0o777:o}); make it yours alone: chmod go-w {folder}")
    return folder
