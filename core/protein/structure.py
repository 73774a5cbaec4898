"""Protein structures as numpy arrays: the frozen :class:`Structure`, its
:class:`BackboneSegment` s and :class:`AtomTable`; read by :mod:`core.protein.reading`,
written back by :mod:`core.protein.writing` (the only modules that touch gemmi, with
:mod:`core.protein.segments`).

Conventions
-----------
- Lengths in Å; coordinate arrays are float64 ``(n, 3)`` and read-only.
- A structure is one model of its file (``Structure.model_number``, counted from 1 in file
  order; the first unless asked). ``Structure.coords`` lists every atom of that model in
  gemmi's traversal order (chain, residue, atom, i.e. file order): all alternate
  locations, hydrogens, hetero groups, waters, nucleic acids.
- Backbone residues are numbered 0 .. n_residues-1 over all segments in order (the
  *residue table*); ``Structure.atom_residue`` maps each atom to that number or -1.
- The backbone arrays use the first conformer (the first altloc met in the residue; the
  first residue of a group sharing one sequence number), but a residue's atom range
  covers all of its atoms and alternate conformers, so they move together.
- An entry without a protein chain (DNA) has no segments; only readers that are asked
  to read one give such a structure.
- A protein chain is cut into segments where consecutive Cα atoms are more than
  :data:`MAX_CA_STEP` apart; residues without Cα are skipped and one-residue segments are
  dropped, each with a message in ``Structure.warnings`` (their atoms keep
  ``atom_residue == -1``). Every segment therefore has at least two residues.
- Secondary structure: from the file's HELIX/SHEET records (mmCIF struct_conf /
  struct_sheet_range) when it has any, otherwise computed by
  :func:`core.protein.secondary_structure.dssp`: 'H' any helix (records of every helix class;
  DSSP α, 3₁₀ and π helices, one residue longer at each end like the wwPDB annotation),
  'E' sheet strand (DSSP ladder), 'C' otherwise.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cache, cached_property
from pathlib import Path

import gemmi
import numpy as np
from numpy.typing import ArrayLike, NDArray

MAX_CA_STEP = 4.2
"""Largest Cα–Cα distance (Å) between consecutive residues of one segment."""

SS_FROM_PDB_RECORDS = "HELIX/SHEET records"
SS_FROM_MMCIF = "mmCIF struct_conf/struct_sheet_range"
SS_COMPUTED = "computed (DSSP, core.protein.secondary_structure)"


@dataclass(frozen=True, eq=False)
class BackboneSegment:
    """A continuous stretch of one protein chain (no Cα–Cα step above MAX_CA_STEP).

    Attributes
    ----------
    chain : str
        Author chain id (may have several characters, may be empty).
    resseq : (N,) int64
        Author residue numbers.
    icode : (N,) str
        Insertion codes, '' where none.
    resname : (N,) str
        Residue names.
    ss : (N,) str
        Secondary structure per residue: 'H', 'E' or 'C'.
    n, ca, c, o : (N, 3) float64, Å
        Backbone atoms (first conformer); ``ca`` is always finite, the others are NaN
        where the atom is missing (all NaN for Cα-only models).
    residue_index : (N,) int64
        Rows of the structure's residue table (consecutive numbers).
    atom_start, atom_stop : (N,) int64
        Residue i owns rows ``atom_start[i]:atom_stop[i]`` of ``Structure.coords``: all
        its atoms, alternate locations and hydrogens included.
    sequence : str
        One-letter codes of the residues (:func:`amino_acid_letter`).
    """

    chain: str
    resseq: NDArray[np.int64]
    icode: NDArray[np.str_]
    resname: NDArray[np.str_]
    ss: NDArray[np.str_]
    n: NDArray[np.float64]
    ca: NDArray[np.float64]
    c: NDArray[np.float64]
    o: NDArray[np.float64]
    residue_index: NDArray[np.int64]
    atom_start: NDArray[np.int64]
    atom_stop: NDArray[np.int64]
    sequence: str

    def __len__(self) -> int:
        return len(self.resseq)

    def atoms(self, i: int) -> slice:
        """Rows of ``Structure.coords`` holding the atoms of residue ``i``."""
        return slice(int(self.atom_start[i]), int(self.atom_stop[i]))

    @cached_property
    def labels(self) -> tuple[str, ...]:
        """Residue labels such as ``'A:LYS48'`` or ``'A:SER52A'``."""
        return tuple(
            f"{self.chain}:{name}{num}{ic}"
            for name, num, ic in zip(self.resname, self.resseq.tolist(), self.icode, strict=True)
        )

    @property
    def summary(self) -> str:
        """E.g. ``'A  MET1–GLY76 (76 residues)'``."""
        return f"{self.chain}  {self.labels[0].split(':')[1]}–{self.labels[-1].split(':')[1]} ({len(self)} residues)"


@cache
def _tabulated_letter(name: str) -> str:
    """gemmi's one-letter code of a residue name (lower case for a modified residue), '' if none."""
    residue = gemmi.find_tabulated_residue(name.strip())
    return residue.one_letter_code.strip() if residue is not None else ""


def amino_acid_letter(name: str, parents: Mapping[str, str] | None = None) -> str:
    """An amino acid's one-letter code by its residue name; a modified one as its parent, by
    gemmi's table (MSE M) or else by the file's own record of it (``parents``, e.g.
    :attr:`AtomTable.parents`: TRN, a Trp, W); X if unknown."""
    code = _tabulated_letter(name) or _tabulated_letter(parents.get(name, "") if parents else "")
    return code.upper() or "X"


def nucleotide_letter(name: str, parents: Mapping[str, str] | None = None) -> str:
    """A nucleotide's one-letter code by its residue name: A, C, G, T, U (I: inosine) for the
    standard ones, its parent's in lower case for a modified one, by gemmi's table (PSU u,
    5CM c) or else by the file's own record of it (``parents``: TCY, a dA, a); N (any
    nucleotide) if unknown."""
    code = _tabulated_letter(name) or _tabulated_letter(parents.get(name, "") if parents else "").lower()
    return code or "N"


@dataclass(frozen=True)
class ChainSummary:
    """Residue counts of one chain id in the first model."""

    name: str
    n_residues: int
    """All residues with this chain id: polymer, ligands, water."""
    n_backbone: int
    """Residues in backbone segments."""
    n_segments: int
    n_nucleotides: int = 0
    """Polymer nucleotides (DNA or RNA)."""
    nucleic_acid: str = ""
    """'DNA', 'RNA' or 'DNA/RNA' by the nucleotides' names; '' without nucleotides, or where
    only modified nucleotides of no known kind say."""


ATOM_CATEGORIES = ("protein", "nucleic", "ligand", "water")
"""Values of ``AtomTable.category``: polymer amino acids, polymer nucleotides, every other
non-water group (ligands, ions, non-polymer hetero groups), and waters."""


@dataclass(frozen=True, eq=False)
class AtomTable:
    """Every atom of the first model, in the order of ``Structure.coords``; read-only arrays.

    Attributes
    ----------
    entry_id : str
    coords : (n_atoms, 3) float64, Å
    name, element, altloc : (n_atoms,) str
        Atom name, element symbol ('C', 'Fe', ...) and alternate location ('' where none).
    resname, chain : (n_atoms,) str
    resseq : (n_atoms,) int64
        Author residue numbers.
    residue : (n_atoms,) int64
        Ordinal of the atom's residue in the model (file order, from 0).
    b_factor : (n_atoms,) float64, Å²
    occupancy : (n_atoms,) float64
    category : (n_atoms,) str
        One of :data:`ATOM_CATEGORIES`.
    parents : dict of str to str
        The standard parent of each modified residue by name, as the file records it (PDB
        MODRES, mmCIF ``_pdbx_struct_mod_residue``): ``{'TCY': 'DA'}``.
    """

    entry_id: str
    coords: NDArray[np.float64]
    name: NDArray[np.str_]
    element: NDArray[np.str_]
    altloc: NDArray[np.str_]
    resname: NDArray[np.str_]
    chain: NDArray[np.str_]
    resseq: NDArray[np.int64]
    residue: NDArray[np.int64]
    b_factor: NDArray[np.float64]
    occupancy: NDArray[np.float64]
    category: NDArray[np.str_]
    parents: Mapping[str, str] = field(default_factory=dict)

    def __len__(self) -> int:
        return len(self.coords)


@dataclass(frozen=True, eq=False)
class Structure:
    """One model of a PDB/mmCIF entry as arrays; see the module docstring.

    Attributes
    ----------
    path : Path
        The file read.
    source_format : str
        'pdb' or 'mmcif'.
    entry_id, title : str
        PDB id (or the file name) and title ('' if none).
    method : str
        How it was determined, as the file says (``'X-RAY DIFFRACTION'``, ``'SOLUTION NMR'``,
        ``'ELECTRON MICROSCOPY'``, several joined by ``'; '``; '' if it says not).
    resolution : float or None
        Å, as the file gives it (None where it gives none, as for NMR).
    coords : (n_atoms, 3) float64, Å
        Every atom of the model in traversal order.
    atom_residue : (n_atoms,) int64
        Residue-table row of each atom, -1 for atoms outside the backbone segments.
    segments : tuple of BackboneSegment
        Empty for an entry without protein (read with ``require_protein=False``).
    ss_source : str
        One of SS_FROM_PDB_RECORDS, SS_FROM_MMCIF, SS_COMPUTED ('' without segments).
    chains : tuple of ChainSummary
        In order of first appearance.
    n_models : int
        Models in the file.
    model_number : int
        The model read, 1 .. n_models in file order; writing replaces its atoms only.
    n_hetero_atoms, n_water_atoms, n_altloc_atoms : int
        Atoms of the model of non-water HETATM groups, of waters, and with an altloc.
    warnings : tuple of str
        What was skipped or ignored while reading.
    atoms : AtomTable
        Names, elements, residues, B-factors and occupancies of the atoms of ``coords``.
    """

    path: Path
    source_format: str
    entry_id: str
    title: str
    method: str
    resolution: float | None
    coords: NDArray[np.float64]
    atom_residue: NDArray[np.int64]
    segments: tuple[BackboneSegment, ...]
    ss_source: str
    chains: tuple[ChainSummary, ...]
    n_models: int
    model_number: int
    n_hetero_atoms: int
    n_water_atoms: int
    n_altloc_atoms: int
    warnings: tuple[str, ...]
    atoms: AtomTable
    _template: gemmi.Structure = field(repr=False)
    _text: str = field(repr=False)
    _encoding: str = field(default="utf-8", repr=False)
    """How ``_text`` was decoded: writing encodes the same way, so unchanged bytes stay as read."""

    @property
    def n_atoms(self) -> int:
        """Atoms of the model (rows of ``coords``)."""
        return len(self.coords)

    @property
    def n_residues(self) -> int:
        """Rows of the residue table (backbone residues of all segments)."""
        return sum(len(s) for s in self.segments)

    @cached_property
    def ligand_rows(self) -> NDArray[np.int64]:
        """Rows of the atoms drawn and carried as ligands: every ``ligand`` atom, and the
        atoms of protein residues no segment holds (GFP's chromophore CRO66, which has no Cα;
        a residue with no bonded neighbour), which the ribbon would otherwise leave unseen."""
        category = self.atoms.category
        return np.flatnonzero((category == "ligand") | ((category == "protein") & (self.atom_residue < 0)))

    def residue_label(self, row: int) -> str:
        """The label of residue-table row ``row``, e.g. ``'A:LYS48'``."""
        return self.residue_labels([row])[0]

    def residue_labels(self, rows: ArrayLike) -> list[str]:
        """The labels of residue-table rows ``rows``, e.g. ``['A:LYS48', 'A:GLU49']``."""
        segments, indices = self.residue_place(np.asarray(rows, dtype=np.int64))
        return [self.segments[segment].labels[index] for segment, index in zip(segments.tolist(), indices.tolist(),
                                                                               strict=True)]

    def residue_place(self, rows: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """The segment holding each residue-table row of ``rows`` and the row's index within it
        (the table lists the segments' residues segment after segment)."""
        starts = np.array([int(s.residue_index[0]) for s in self.segments], dtype=np.int64)
        segment = np.searchsorted(starts, rows, side="right") - 1
        return segment, np.asarray(rows) - starts[segment]


def ca_rows(structure: Structure) -> np.ndarray:
    """Row of ``structure.coords`` holding the Cα of each backbone residue, (n_residues,)."""
    ca = np.concatenate([np.empty((0, 3)), *(s.ca for s in structure.segments)])
    owner = structure.atom_residue
    candidates = np.flatnonzero(owner >= 0)
    match = candidates[np.all(structure.coords[candidates] == ca[owner[candidates]], axis=1)]
    residues, first = np.unique(owner[match], return_index=True)
    if len(residues) != len(ca):
        raise ValueError("every backbone residue must own the atom at its Cα position")
    return match[first]


def frozen(array: np.ndarray) -> np.ndarray:
    """``array`` as a contiguous, read-only array: how a structure keeps its arrays."""
    array = np.ascontiguousarray(array)
    array.flags.writeable = False
    return array
