"""PySide's import hook reads the whole source of every module imported after Qt, to learn
whether it uses PySide's ``__feature__`` switches (``from __feature__ import snake_case``), and
:mod:`linecache` keeps every line it read: about 55 MB and 0.08 s for the editor's imports
(numpy, scipy, VTK, pyvista, matplotlib), held for the life of the process.
:func:`forget_sources_read_by_pyside` keeps the check and drops what it left in the cache."""

from __future__ import annotations

import functools
import linecache
import sys
from types import ModuleType


def forget_sources_read_by_pyside() -> None:
    """Make PySide's check of each newly imported module forget the source it read (once PySide6
    is imported; a PySide without that check is left as it is)."""
    feature = sys.modules.get("shibokensupport.feature")
    check = getattr(feature, "_mod_uses_pyside", None)
    if check is None or hasattr(check, "__wrapped__"):
        return

    @functools.wraps(check)
    def uses_pyside(module: ModuleType) -> bool:
        cached = len(linecache.cache)
        try:
            return check(module)
        finally:  # the lines it added are the last ones in the cache
            while len(linecache.cache) > cached and linecache.cache:
                linecache.cache.popitem()

    feature._mod_uses_pyside = uses_pyside  # type: ignore[union-attr]
