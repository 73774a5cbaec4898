"""Residues named as people type them: ``A:45``, ``45``, ``A45``, ``A:LYS45``, ``A:52A``, ``A:40-50``."""

from __future__ import annotations

import re

import numpy as np

from core.protein.structure import Structure

_RESIDUE = re.compile(r"(?:(?P<chain>[A-Za-z0-9]{1,4})\s*[:/]\s*|(?P<letter>[A-Za-z])(?=-?\d))?"
                      r"(?P<name>[A-Za-z]{3})?(?P<first>-?\d+)(?P<icode>[A-Za-z]?)"
                      r"(?:\s*(?:-|–|\.\.)\s*(?P<last>-?\d+)(?P<last_icode>[A-Za-z]?))?")


def find_residues(structure: Structure, text: str, chain: str | None = None) -> np.ndarray:
    """Residue-table rows named by ``text``: one residue (``A:45``, ``45``, ``A45``, ``A:LYS45``,
    ``A:52A``) or a range (``A:40-50``), in ``chain`` when the text names none (any chain
    when ``chain`` is None, the first that has it). Raises ValueError naming what is missing."""
    match = _RESIDUE.fullmatch(text.strip())
    if match is None:
        raise ValueError(f"cannot read {text!r} as a residue: type e.g. A:45, 45 or A:40-50")
    named = match["chain"] or match["letter"]
    chains = [s.chain for s in structure.segments]
    if named is not None and named not in chains:
        raise ValueError(f"no chain {named} with a protein backbone (chains: {', '.join(dict.fromkeys(chains))})")
    wanted = named if named is not None else chain
    first = _row(structure, wanted, int(match["first"]), match["icode"].upper(), match["name"], text)
    if match["last"] is None:
        return np.array([first])
    last = _row(structure, wanted if wanted is not None else _chain_of(structure, first), int(match["last"]),
                match["last_icode"].upper(), None, text)
    low, high = sorted((first, last))
    if _chain_of(structure, low) != _chain_of(structure, high):
        raise ValueError(f"{text!r} spans two chains")
    return np.arange(low, high + 1)


def _row(structure: Structure, chain: str | None, number: int, icode: str, name: str | None, text: str) -> int:
    for segment in structure.segments:
        if chain is not None and segment.chain != chain:
            continue
        hit = np.flatnonzero((segment.resseq == number) & (segment.icode == icode))
        if len(hit) and (name is None or segment.resname[hit[0]] == name.upper()):
            return int(segment.residue_index[hit[0]])
    where = f" in chain {chain}" if chain is not None else ""
    raise ValueError(f"no residue {text.strip()}{where}")


def _chain_of(structure: Structure, row: int) -> str:
    return next(s.chain for s in structure.segments if s.residue_index[0] <= row <= s.residue_index[-1])
