"""The residues, atoms and groups of a structure that a selection names, in any of the
syntaxes :mod:`core.protein.selection` reads: ``A:45``, ``/A:40-50``, ``chain A and resi 45-50``,
lists of these, and these combined by PyMOL's and ChimeraX's operators, among them the residues
near others or a ligand, as both select a binding site (``byres resn HEM around 5``,
``within 5 of A:45``; ``:HEM :<5``), with classes of residues and groups (``ss H``, ``helix``,
``polymer``, ``organic``, ``solvent``, ...): ``chain A and ss H``, ``/A:40-60 & :HIS``,
``byres organic around 4 and not resn HOH``."""

from __future__ import annotations

import re
from dataclasses import dataclass, replace

import numpy as np
from scipy.spatial import cKDTree

from core.protein.selection import (
    CHAIN,
    HELP,
    NAME,
    OPERATORS,
    Named,
    Operation,
    Term,
    atom_parts,
    parse,
    read,
    read_parts,
    tokens,
)
from core.protein.structure import Structure

MAX_REACH = 50.0
"""Å: the farthest a selection of the residues near others reaches."""


def find_residues(structure: Structure, text: str, chain: str | None = None, coords: np.ndarray | None = None
                  ) -> np.ndarray:
    """Residue-table rows named by ``text``, in increasing order: one residue (``A:45``, ``45``,
    ``A45``, ``A:LYS45``, ``A:52A``), a range (``A:40-50``), a whole chain (``/A``, ``chain A``),
    the residues of a name (``resn HIS``, ``:his``: in every chain where none is named) or a
    list of them (``A:40-42, B:45``, ``/A:40-42,50``, ``resi 40-42+50``), in any syntax of the
    module's; a part names ``chain`` when neither it nor a part before it in its list names one
    (any chain when ``chain`` is None, the first that has it). Or these combined by operators
    (``chain A and ss H``, ``resi 40-45 or resi 90``), among them the residues with an atom
    within a distance of others or of a ligand (``byres resn HEM around 5``), measured on
    ``coords`` (every atom's, Å; default: as read); in a combined selection, as in PyMOL, a
    residue number without a chain names that residue in every chain, a range every number in
    it, and what the entry lacks selects nothing. Raises ValueError naming what is missing (of
    a combined selection, where it selects no residue) or how to type it."""
    coords = structure.coords if coords is None else coords
    if not OPERATORS.isdisjoint(kind for kind, _ in tokens(text)):
        return _selected(structure, text, coords)
    parts = read_parts(text.strip())
    if parts is None:
        return _selected(structure, text, coords)
    if len(parts) == 1:
        return _rows(structure, *parts[0], chain)
    return np.unique(np.concatenate([_rows(structure, part, named, chain) for part, named in parts]))


def _selected(structure: Structure, text: str, coords: np.ndarray) -> np.ndarray:
    """The backbone residues of a selection combined by operators (:mod:`core.protein.selection`),
    its terms read in every chain where they name none; a term that names nothing there is
    empty, as in PyMOL (``(chain A or chain B) and resi 10-20`` of a one-chain protein)."""
    atoms, missing = _combined_atoms(structure, text, coords)
    rows = np.unique(structure.atom_residue[atoms & (structure.atom_residue >= 0)])
    if not len(rows):
        raise ValueError(f"no residue of a protein backbone is in {text.strip()!r}" + _missing(missing))
    return rows


def _combined_atoms(structure: Structure, text: str, coords: np.ndarray) -> tuple[np.ndarray, list[str]]:
    """(n_atoms,) bool: the atoms of the whole residues and groups that a selection combined by
    operators selects, and what its terms name that the structure lacks."""
    missing: list[str] = []
    return _atoms_of(structure, _merged(parse(text)), coords, missing), missing


def _missing(missing: list[str]) -> str:
    return f" ({'; '.join(dict.fromkeys(missing))})" if missing else ""


@dataclass(frozen=True, eq=False)
class Selected:
    """What a selection names: backbone residues (residue-table rows) and whole groups outside
    the backbone segments (ligands, ions, waters, nucleotides: coordinate rows), both sorted."""

    residues: np.ndarray
    groups: np.ndarray

    @classmethod
    def of(cls, structure: Structure, residues: np.ndarray | list[int], groups: np.ndarray | list[int] = ()
           ) -> Selected:
        """The selection of residue-table rows ``residues`` and of the coordinate rows ``groups``
        (each once, sorted); ValueError for a row the structure lacks, or a group's inside a segment."""
        residues, groups = (np.unique(np.asarray(rows, dtype=np.int64)) for rows in (residues, groups))
        if len(residues) and not 0 <= residues[0] <= residues[-1] < structure.n_residues:
            raise ValueError(f"residue rows must be in [0, {structure.n_residues - 1}]")
        if len(groups) and not (0 <= groups[0] <= groups[-1] < structure.n_atoms
                                and (structure.atom_residue[groups] < 0).all()):
            raise ValueError("a selected group's rows must be atoms outside the backbone segments")
        return cls(residues, groups)

    def labels(self, structure: Structure) -> list[str]:
        """``['A:ASP189', ..., 'A:BEN1']``: the residues, then each group once."""
        return (structure.residue_labels(self.residues)
                + [group_label(structure, int(row)) for row in self.groups[group_starts(structure, self.groups)]])


def _named(structure: Structure, text: str, parts: list[tuple[str, Named]], chain: str | None) -> Selected:
    """The residues and groups of a name or a list of them (:func:`find_selection`): each part a
    residue, range or chain as :func:`find_residues` reads it, else the groups it names (a
    range: every number in it, residues and groups, in ``chain`` where it names none, as
    PyMOL's ``resi``); a part that names nothing selects nothing, and ValueError where none
    names anything."""
    residues, groups, missing = [], [], []
    for part, named in parts:
        try:
            residues.append(_rows(structure, part, named, chain))
            continue
        except ValueError as error:
            missing.append(str(error))
        if named.last is not None:
            try:
                atoms = _part_atoms(structure, part, named if named.chain is not None else replace(named, chain=chain))
            except ValueError:
                continue
            residues.append(structure.atom_residue[atoms & (structure.atom_residue >= 0)])
            groups.append(np.flatnonzero(atoms & (structure.atom_residue < 0)))
        elif len(parts) == 1 and (found := find_group(structure, text, chain, several=True)) is not None:
            groups.append(found)  # one group (``A:HEM142``, ``B:PO4``), or every one of its name (``/A:HOH``)
        else:  # or of a chain (a DNA strand, ``/B``)
            groups.append(np.flatnonzero(_group_atoms(structure, named, chain)))
    residues = np.unique(np.concatenate(residues or [np.empty(0, dtype=np.int64)]))
    groups = np.unique(np.concatenate(groups or [residues[:0]]))
    if not len(residues) and not len(groups):
        raise ValueError("; ".join(dict.fromkeys(missing)))
    return Selected(residues, groups.astype(np.int64))


def groups_of(structure: Structure, rows: np.ndarray) -> np.ndarray:
    """The coordinate rows of the whole groups outside the backbone segments that hold atoms ``rows``, sorted."""
    residue = structure.atoms.residue
    return np.flatnonzero(np.isin(residue, residue[rows]) & (structure.atom_residue < 0))


def group_starts(structure: Structure, groups: np.ndarray) -> np.ndarray:
    """Indices into ``groups`` (sorted coordinate rows of whole groups) where each group begins."""
    return np.flatnonzero(np.r_[True, np.diff(structure.atoms.residue[groups]) != 0]) if len(groups) else groups[:0]


def find_selection(structure: Structure, text: str, chain: str | None = None, coords: np.ndarray | None = None
                   ) -> Selected:
    """The residues and groups named by ``text``: residues as :func:`find_residues` reads them,
    or one group as :func:`find_group` does (``A:HEM``, ``resn BEN``), or every group of a name
    (``resn HOH``); in a selection combined by operators, the groups it holds beside its
    residues (``resn BEN or byres resn BEN around 4``: a ligand and its pocket). Raises
    ValueError where it names nothing, or how to type it."""
    coords = structure.coords if coords is None else coords
    if OPERATORS.isdisjoint(kind for kind, _ in tokens(text)):  # names, or a class (``all``: below)
        if (parts := read_parts(text.strip())) is not None:
            return _named(structure, text, parts, chain)
        if (groups := find_group(structure, text, chain, several=True)) is not None:  # ``A:HEM``
            return Selected(groups[:0], groups)
    atoms, missing = _combined_atoms(structure, text, coords)
    selected = Selected(np.unique(structure.atom_residue[atoms & (structure.atom_residue >= 0)]),
                        np.flatnonzero(atoms & (structure.atom_residue < 0)))
    if not len(selected.residues) and not len(selected.groups):
        raise ValueError(f"{text.strip()!r} selects nothing here" + _missing(missing))
    return selected


def _merged(tree: Term | Operation) -> Term | Operation:
    """``tree`` with each ``and`` of terms that read as one (PyMOL's ``resn HEM and chain A``,
    the hemes of chain A; ``chain B and resi 45``) made one term."""
    if isinstance(tree, Term):
        return tree
    operands = tuple(_merged(operand) for operand in tree.operands)
    if tree.kind == "and" and all(isinstance(operand, Term) for operand in operands):
        joined = " and ".join(operand.text for operand in operands)
        if read(joined) is not None:
            return Term(joined)
    return Operation(tree.kind, operands, tree.reach)


def _atoms_of(structure: Structure, tree: Term | Operation, coords: np.ndarray, missing: list[str]) -> np.ndarray:
    """(n_atoms,) bool: the atoms of the whole residues and groups ``tree`` selects; what its
    terms name that the structure lacks is added to ``missing``."""
    if isinstance(tree, Term):
        chosen = _term_atoms(structure, tree.text, missing)
    else:
        first = _atoms_of(structure, tree.operands[0], coords, missing)
        if tree.kind == "not":
            chosen = ~first
        elif tree.kind in ("and", "or"):
            chosen, combine = first, np.logical_and if tree.kind == "and" else np.logical_or
            for operand in tree.operands[1:]:
                combine(chosen, _atoms_of(structure, operand, coords, missing), out=chosen)
        else:
            if not 0.0 < tree.reach <= MAX_REACH:
                raise ValueError(f"a distance of {tree.reach:g} Å: give one above 0 and at most {MAX_REACH:g} Å")
            near = np.zeros(len(first), dtype=bool)
            if first.any():
                near = cKDTree(coords[first]).query_ball_point(coords, tree.reach, return_length=True) > 0
            chosen = near & ~first if tree.kind == "around" else near | first
    residue = structure.atoms.residue
    return np.isin(residue, residue[chosen])  # whole residues and groups, as PyMOL's byres


def _term_atoms(structure: Structure, text: str, missing: list[str]) -> np.ndarray:
    """(n_atoms,) bool: the atoms ``text`` names, in every chain where it names none: a residue,
    range, chain, name or list as :func:`find_residues` reads them, or a class of them. A part
    the structure lacks selects nothing and is added to ``missing``; ValueError for a text
    that is none of these."""
    atoms, key = structure.atoms, text.strip().lower()
    if key in _CLASSES:
        return _CLASSES[key](structure)
    if match := re.fullmatch(r"(?:ss|secondary)\s+(?P<codes>[a-z'+]+)", key):
        codes = {_SS_CODES.get(code, "?") for code in match["codes"].replace("''", "l").split("+")}
        if "?" in codes:
            raise ValueError(f"{text.strip()!r}: secondary structure is H (helix), S (strand) or L (loop)")
        return _ss_atoms(structure, codes)
    parts = read_parts(text.strip())
    if parts is None:
        raise ValueError(f"cannot read {text.strip()!r} as residues: {HELP}")
    chosen = np.zeros(len(atoms), dtype=bool)
    for part, named in parts:
        try:
            chosen |= _part_atoms(structure, part, named)
        except ValueError as error:
            missing.append(str(error))
    return chosen


def _part_atoms(structure: Structure, part: str, named: Named) -> np.ndarray:
    """(n_atoms,) bool: the atoms of one part of a term (ValueError where it names nothing)."""
    atoms = structure.atoms
    if named.first is None:  # a chain, or every residue or group of a name
        here = (atoms.chain == named.chain) if named.chain is not None else np.ones(len(atoms), dtype=bool)
        if named.name is None and not here.any():
            raise ValueError(f"no chain {named.chain}")
        if named.name is not None:
            here &= atoms.resname == named.name.upper()
        if not here.any():
            raise ValueError(f"no residue or ligand {named.name.upper()}"
                             + (f" in chain {named.chain}" if named.chain is not None else ""))
        return here
    numbered = (structure.atom_residue < 0) & ((atoms.chain == named.chain) if named.chain is not None else True)
    if named.name is not None:
        numbered &= atoms.resname == named.name.upper()
    if named.last is not None and not named.icode and not named.last_icode:  # every number in the range, as PyMOL
        low, high = sorted((named.first, named.last))
        rows = np.concatenate([s.residue_index[(s.resseq >= low) & (s.resseq <= high)
                                               & ((s.resname == named.name.upper()) if named.name else True)]
                               for s in structure.segments if named.chain in (None, s.chain)] or [np.empty(0, int)])
        chosen = np.isin(structure.atom_residue, rows) | (numbered & (atoms.resseq >= low) & (atoms.resseq <= high))
        if not chosen.any():
            raise ValueError(f"no residue {part.strip()}" + (f" in chain {named.chain}" if named.chain else " in any chain"))
        return chosen
    chains = [named.chain] if named.chain is not None else list(dict.fromkeys(s.chain for s in structure.segments))
    found, missing = [np.empty(0, dtype=np.int64)], f"no residue {part.strip()} in any chain"
    for chain in chains:
        try:
            found.append(_rows(structure, part, replace(named, chain=chain), None))
        except ValueError as error:
            missing = str(error) if named.chain is not None else missing
    chosen = np.isin(structure.atom_residue, np.concatenate(found))
    if named.last is None and not named.icode:  # a ligand, ion or water of the number, as PyMOL's resi
        chosen |= numbered & (atoms.resseq == named.first)
    if not chosen.any():
        raise ValueError(missing)
    return chosen


def _ss_atoms(structure: Structure, codes: set[str]) -> np.ndarray:
    """(n_atoms,) bool: the atoms of the backbone residues whose secondary structure is one of ``codes``."""
    ss = np.concatenate([s.ss for s in structure.segments]) if structure.segments else np.empty(0, str)
    return np.isin(structure.atom_residue, np.flatnonzero(np.isin(ss, sorted(codes))))


def _ligand_groups(structure: Structure, carbon: bool) -> np.ndarray:
    """(n_atoms,) bool: the ligand groups with (``carbon``) or without a carbon atom."""
    atoms = structure.atoms
    ligand = atoms.category == "ligand"
    organic = np.isin(atoms.residue, atoms.residue[ligand & (atoms.element == "C")])
    return ligand & (organic if carbon else ~organic)


_SS_CODES = {"h": "H", "s": "E", "e": "E", "l": "C", "c": "C"}
"""PyMOL's secondary-structure codes (H helix, S strand, L or '' loop) as the residue table's."""
_CLASSES = {
    "all": lambda structure: np.ones(structure.n_atoms, dtype=bool),
    "*": lambda structure: np.ones(structure.n_atoms, dtype=bool),
    "polymer": lambda structure: np.isin(structure.atoms.category, ("protein", "nucleic")),
    "protein": lambda structure: structure.atoms.category == "protein",
    "organic": lambda structure: _ligand_groups(structure, carbon=True),
    "ligand": lambda structure: _ligand_groups(structure, carbon=True),
    "inorganic": lambda structure: _ligand_groups(structure, carbon=False),
    "ions": lambda structure: _ligand_groups(structure, carbon=False),
    "solvent": lambda structure: structure.atoms.category == "water",
    "helix": lambda structure: _ss_atoms(structure, {"H"}),
    "strand": lambda structure: _ss_atoms(structure, {"E"}),
    "coil": lambda structure: _ss_atoms(structure, {"C"}),
}
"""Classes of atoms by name, as PyMOL (``polymer``, ``organic``, ``inorganic``, ``solvent``) and
ChimeraX (``protein``, ``ligand``, ``ions``, ``solvent``, ``helix``, ``strand``, ``coil``) name them."""


def _rows(structure: Structure, text: str, named: Named, chain: str | None) -> np.ndarray:
    """The rows of one residue, range or chain, ``named`` by ``text``."""
    chains = [s.chain for s in structure.segments]
    if named.chain is not None and named.chain not in chains:
        every = dict.fromkeys(structure.atoms.chain.tolist())
        if named.chain in every:  # a chain of DNA, RNA or ligands only
            raise ValueError(f"no residue {text.strip()} in chain {named.chain} (it has no protein backbone)")
        known = ", ".join(chain or "none (the file names no chain)" for chain in every) or "none"
        raise ValueError(f"no chain {named.chain} (chains: {known})")
    if named.first is None:  # a whole chain, or the residues of a name (in every chain where none is named)
        segments = [s for s in structure.segments if named.chain in (None, s.chain)]
        rows = np.concatenate([s.residue_index for s in segments] or [np.empty(0, dtype=np.int64)])
        if named.name is None:
            return rows
        rows = rows[np.concatenate([s.resname for s in segments] or [np.empty(0, dtype=str)]) == named.name.upper()]
        if not len(rows):
            raise ValueError(f"no residue {named.name.upper()}" + (f" in chain {named.chain}" if named.chain else ""))
        return rows
    wanted = named.chain if named.chain is not None else chain
    first = _row(structure, wanted, named.first, named.icode, named.name, text)
    if named.last is None:
        return np.array([first])
    last = _row(structure, wanted if wanted is not None else _chain_of(structure, first), named.last,
                named.last_icode, None, text)
    low, high = sorted((first, last))
    if _chain_of(structure, low) != _chain_of(structure, high):
        raise ValueError(f"{text.strip()!r} spans two chains")
    return np.arange(low, high + 1)


def find_atom(structure: Structure, text: str, chain: str | None = None) -> int:
    """Coordinate row of the atom named by ``text``: one residue as :func:`find_residues` reads
    it and an atom name, ``A:LYS48 NZ``, ``48 CA`` (in ``chain``), ``/A:48@NZ`` (ChimeraX),
    ``A/48/NZ`` or ``chain A and resi 48 and name NZ`` (PyMOL); or of a group outside the
    protein's backbone, a ligand, ion, water or nucleotide, by its number or name
    (``A:HEM FE``, ``/A:HEM@FE``, ``A:142 FE``, ``/B:DA5@P``); the first alternate location.
    Raises ValueError naming what is missing or how to type it."""
    residue, name = atom_parts(text.strip())
    if not name:
        raise ValueError(f"cannot read {text.strip()!r} as an atom: type e.g. A:48 NZ, /A:48@NZ or A/48/NZ")
    try:
        rows = find_residues(structure, residue, chain)
    except ValueError:
        group = find_group(structure, residue, chain)
        if group is None:
            raise
        atoms = group[structure.atoms.name[group] == name.upper()]
        if not len(atoms):
            raise ValueError(f"no atom {name.upper()} in {group_label(structure, int(group[0]))}") from None
        return int(atoms[0])
    if len(rows) != 1:
        raise ValueError(f"{text.strip()!r} names {len(rows)} residues: name one, and an atom of it")
    atoms = np.flatnonzero((structure.atom_residue == rows[0]) & (structure.atoms.name == name.upper()))
    if not len(atoms):
        raise ValueError(f"no atom {name.upper()} in {_label(structure, int(rows[0]))}")
    return int(atoms[0])


def find_group(structure: Structure, text: str, chain: str | None = None, *, several: bool = False
               ) -> np.ndarray | None:
    """Coordinate rows of the one group outside the backbone segments (a ligand, ion, water or
    nucleotide) named by ``text``: by its number, name or both, as residues are named
    (``A:142``, ``A:HEM142``, ``/A:HEM``, ``resn HEM``), ``A:HEM``, or its label (``A:SO4290``,
    ``:ADP999`` where the file names no chain), in ``chain`` when the text names none and that
    chain has it. None where the text names no such group;
    ValueError where it names several, unless ``several`` (then all of them)."""
    readings = [read(text.strip())]  # B:PO4 reads as residue 4 named PO, and as the group PO4 of chain B
    if match := re.fullmatch(rf"(?P<chain>{CHAIN})\s*:\s*(?P<name>{NAME})", text.strip()):
        readings.append(Named(match["chain"], name=match["name"]))
    if label := re.fullmatch(rf"(?P<chain>{CHAIN})?:(?P<rest>[A-Za-z0-9]{{2,12}})", text.strip()):
        rest = label["rest"]  # a group's label, A:SO4290 or :0QH256: its name, of one to three characters, and number
        readings += [Named(label["chain"] or "", int(rest[k:]), name=rest[:k]) for k in (3, 2, 1)
                     if re.fullmatch(NAME, rest[:k]) and rest[k:].isdigit()]
    readings = [named for named in readings if named is not None and named.last is None
                and (named.first is not None or named.name is not None)]
    if not readings:
        return None
    rows = np.empty(0, dtype=np.int64)
    for named in readings:
        rows = np.flatnonzero(_group_atoms(structure, named, chain))
        if len(rows):
            break
    if not len(rows):
        if match:
            raise ValueError(f"no residue or group {match['name'].upper()} in chain {match['chain']}")
        return None
    groups, first = np.unique(structure.atoms.residue[rows], return_index=True)
    if len(groups) > 1 and not several:
        names = [group_label(structure, int(row)) for row in rows[np.sort(first)][:6].tolist()]
        raise ValueError(f"{text.strip()!r} names {len(groups)} groups ({', '.join(names)}"
                         + (", ..." if len(groups) > 6 else "") + "): name one")
    return rows


def _group_atoms(structure: Structure, named: Named, chain: str | None) -> np.ndarray:
    """(n_atoms,) bool: the atoms outside the backbone segments of the groups ``named``, in
    ``chain`` when it names none and that chain has them."""
    atoms = structure.atoms
    chosen = structure.atom_residue < 0
    if named.first is not None:
        chosen &= atoms.resseq == named.first
    if named.name is not None:
        chosen &= atoms.resname == named.name.upper()
    where = named.chain if named.chain is not None else chain
    if where is not None and (named.chain is not None or (chosen & (atoms.chain == where)).any()):
        chosen &= atoms.chain == where
    return chosen


def group_label(structure: Structure, row: int) -> str:
    """``A:HEM142``: the group of atom ``row`` (``:ADP999`` where the file names no chain)."""
    atoms = structure.atoms
    return f"{atoms.chain[row]}:{atoms.resname[row]}{atoms.resseq[row]}"


def _label(structure: Structure, row: int) -> str:
    segment = next(s for s in structure.segments if s.residue_index[0] <= row <= s.residue_index[-1])
    return str(segment.labels[row - segment.residue_index[0]])


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
