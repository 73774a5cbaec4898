"""Protein structures from PDB/mmCIF files as numpy arrays, and edited coordinates back.

The only module of core/ that touches gemmi. :func:`read_structure` returns a frozen
:class:`Structure`: the coordinates of every atom of the first model plus the protein
backbone cut into continuous :class:`BackboneSegment` s; :func:`write_structure` writes
new coordinates for the same atoms; :func:`read_atoms` returns just the :class:`AtomTable`
of any entry (DNA without protein included), for surfaces and maps. The gemmi objects stay
private inside ``Structure``.

Conventions
-----------
- Lengths in Å; coordinate arrays are float64 ``(n, 3)`` and read-only.
- ``Structure.coords`` lists every atom of the first model in gemmi's traversal order
  (chain, residue, atom, i.e. file order): all alternate locations, hydrogens, hetero
  groups, waters, nucleic acids.
- Backbone residues are numbered 0 .. n_residues-1 over all segments in order (the
  *residue table*); ``Structure.atom_residue`` maps each atom to that number or -1.
- The backbone arrays use the first conformer (the first altloc met in the residue; the
  first residue of a group sharing one sequence number), but a residue's atom range
  covers all of its atoms and alternate conformers, so they move together.
- A protein chain is cut into segments where consecutive Cα atoms are more than
  :data:`MAX_CA_STEP` apart; residues without Cα are skipped and one-residue segments are
  dropped, each with a message in ``Structure.warnings`` (their atoms keep
  ``atom_residue == -1``). Every segment therefore has at least two residues.
- Secondary structure: from the file's HELIX/SHEET records (mmCIF struct_conf /
  struct_sheet_range) when it has any, otherwise computed by
  :func:`core.secondary_structure.dssp`: 'H' any helix (records of every helix class;
  DSSP α, 3₁₀ and π helices, one residue longer at each end like the wwPDB annotation),
  'E' sheet strand (DSSP ladder), 'C' otherwise.
"""

from __future__ import annotations

import contextlib
import gzip
import os
import tempfile
import zlib
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path

import gemmi
import numpy as np
from numpy.typing import NDArray

from .secondary_structure import dssp

MAX_CA_STEP = 4.2
"""Largest Cα–Cα distance (Å) between consecutive residues of one segment."""

SS_FROM_PDB_RECORDS = "HELIX/SHEET records"
SS_FROM_MMCIF = "mmCIF struct_conf/struct_sheet_range"
SS_COMPUTED = "computed (DSSP, core.secondary_structure)"

_BACKBONE = ("N", "CA", "C", "O")
_PEPTIDE = (gemmi.PolymerType.PeptideL, gemmi.PolymerType.PeptideD)
_PDB_SUFFIXES = (".pdb", ".ent")
_MMCIF_SUFFIXES = (".cif", ".mmcif")
_COORDINATE_RECORDS = ("ATOM", "HETATM", "ANISOU", "MODEL", "TER")
# Order of the PDB header records (wwPDB format 3.3), used to put back the records of the
# input that gemmi does not write (COMPND, SOURCE, AUTHOR, JRNL, REVDAT, FORMUL, ...).
_PDB_HEADER_ORDER = (
    "HEADER", "OBSLTE", "TITLE", "SPLIT", "CAVEAT", "COMPND", "SOURCE", "KEYWDS", "EXPDTA",
    "NUMMDL", "MDLTYP", "AUTHOR", "REVDAT", "SPRSDE", "JRNL", "REMARK", "DBREF", "DBREF1",
    "DBREF2", "SEQADV", "SEQRES", "MODRES", "HET", "HETNAM", "HETSYN", "FORMUL", "HELIX",
    "SHEET", "SSBOND", "LINK", "CISPEP", "SITE", "CRYST1", "ORIGX1", "ORIGX2", "ORIGX3",
    "SCALE1", "SCALE2", "SCALE3", "MTRIX1", "MTRIX2", "MTRIX3",
)  # fmt: skip


class StructureError(ValueError):
    """A file that cannot be used as a protein structure, or a bad argument to a writer."""


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


@dataclass(frozen=True)
class ChainSummary:
    """Residue counts of one chain id in the first model."""

    name: str
    n_residues: int
    """All residues with this chain id: polymer, ligands, water."""
    n_backbone: int
    """Residues in backbone segments."""
    n_segments: int


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

    def __len__(self) -> int:
        return len(self.coords)


@dataclass(frozen=True, eq=False)
class Structure:
    """The first model of a PDB/mmCIF entry as arrays; see the module docstring.

    Attributes
    ----------
    path : Path
        The file read.
    source_format : str
        'pdb' or 'mmcif'.
    entry_id, title : str
        PDB id (or the file name) and title ('' if none).
    coords : (n_atoms, 3) float64, Å
        Every atom of the first model in traversal order.
    atom_residue : (n_atoms,) int64
        Residue-table row of each atom, -1 for atoms outside the backbone segments.
    segments : tuple of BackboneSegment
    ss_source : str
        One of SS_FROM_PDB_RECORDS, SS_FROM_MMCIF, SS_COMPUTED.
    chains : tuple of ChainSummary
        In order of first appearance.
    n_models : int
        Models in the file (only the first is read and edited).
    n_hetero_atoms, n_water_atoms, n_altloc_atoms : int
        First-model atoms of non-water HETATM groups, of waters, and with an altloc.
    warnings : tuple of str
        What was skipped or ignored while reading.
    atoms : AtomTable
        Names, elements, residues, B-factors and occupancies of the atoms of ``coords``.
    """

    path: Path
    source_format: str
    entry_id: str
    title: str
    coords: NDArray[np.float64]
    atom_residue: NDArray[np.int64]
    segments: tuple[BackboneSegment, ...]
    ss_source: str
    chains: tuple[ChainSummary, ...]
    n_models: int
    n_hetero_atoms: int
    n_water_atoms: int
    n_altloc_atoms: int
    warnings: tuple[str, ...]
    atoms: AtomTable
    _template: gemmi.Structure = field(repr=False)
    _text: str = field(repr=False)

    @property
    def n_atoms(self) -> int:
        """Atoms of the first model (rows of ``coords``)."""
        return len(self.coords)

    @property
    def n_residues(self) -> int:
        """Rows of the residue table (backbone residues of all segments)."""
        return sum(len(s) for s in self.segments)


# ----------------------------------------------------------------------------- reading


def read_structure(path: str | os.PathLike[str]) -> Structure:
    """Read a PDB or mmCIF file (optionally gzipped); the format is taken from the content.

    Parameters
    ----------
    path : str or path-like

    Returns
    -------
    Structure

    Raises
    ------
    StructureError
        Missing, empty or unreadable file, no atoms, no protein chain, or non-finite
        coordinates; the message names the file.
    """
    path = Path(path)
    text, fmt, st, atoms = _read_model(path)
    notes: list[str] = []
    groups = _residue_groups(atoms)
    runs = _backbone_runs(atoms, groups, notes)
    if not runs:
        raise StructureError(
            f"{path}: no protein chain (no two consecutive amino-acid residues with Cα)"
        )
    rows = np.concatenate(runs)
    ss, ss_source = _secondary_structure(st, fmt, atoms, groups, runs, notes)
    segments = _make_segments(atoms, groups, runs, ss)
    return Structure(
        path=path,
        source_format=fmt,
        entry_id=st.name,
        title=_info(st, "_struct.title"),
        coords=_frozen(atoms.coords),
        atom_residue=_frozen(_atom_residue(len(atoms.coords), groups, rows)),
        segments=segments,
        ss_source=ss_source,
        chains=_chain_summaries(atoms, segments),
        n_models=len(st),
        n_hetero_atoms=atoms.n_hetero,
        n_water_atoms=atoms.n_water,
        n_altloc_atoms=atoms.n_altloc,
        warnings=tuple(notes),
        atoms=_atom_table(st.name, atoms),
        _template=st,
        _text=text,
    )


def read_atoms(path: str | os.PathLike[str]) -> AtomTable:
    """Read every atom of the first model of a PDB or mmCIF file (optionally gzipped).

    Unlike :func:`read_structure` this needs no protein chain (e.g. a DNA duplex).

    Raises
    ------
    StructureError
        Missing, empty or unreadable file, no atoms, or non-finite coordinates.
    """
    path = Path(path)
    _, _, st, atoms = _read_model(path)
    return _atom_table(st.name, atoms)


def _read_model(path: Path) -> tuple[str, str, gemmi.Structure, _Atoms]:
    """Text, format, parsed structure and scanned first model of a file with finite atoms."""
    text = _read_text(path)
    fmt = "mmcif" if _looks_like_mmcif(text) else "pdb"
    st = _parse(text, fmt, path)
    atoms = _scan_model(st[0])
    if len(atoms.coords) == 0:
        raise StructureError(f"{path}: not a structure file (no atoms found)")
    if not np.isfinite(atoms.coords).all():
        bad = int((~np.isfinite(atoms.coords).all(axis=1)).sum())
        raise StructureError(f"{path}: {bad} atom(s) have non-finite coordinates")
    return text, fmt, st, atoms


def _atom_table(entry_id: str, atoms: _Atoms) -> AtomTable:
    counts = atoms.stop - atoms.start

    def per_atom(values: object, dtype: type) -> np.ndarray:
        return _frozen(np.repeat(np.asarray(values, dtype=dtype), counts))

    category = np.select(
        [atoms.water, atoms.protein, atoms.nucleic], ["water", "protein", "nucleic"], "ligand"
    )
    return AtomTable(
        entry_id=entry_id,
        coords=_frozen(atoms.coords),
        name=_frozen(np.array(atoms.atom_name, dtype=str).reshape(-1)),
        element=_frozen(np.array(atoms.element, dtype=str).reshape(-1)),
        altloc=_frozen(np.array(atoms.altloc, dtype="<U1").reshape(-1)),
        resname=per_atom(atoms.resname, str),
        chain=per_atom(atoms.chain, str),
        resseq=per_atom(atoms.seq, np.int64),
        residue=per_atom(np.arange(len(counts)), np.int64),
        b_factor=_frozen(np.array(atoms.b_factor, dtype=np.float64)),
        occupancy=_frozen(np.array(atoms.occupancy, dtype=np.float64)),
        category=per_atom(category, str),
    )


def _read_text(path: Path) -> str:
    """File content as text, gunzipped when it starts with the gzip magic bytes."""
    if not path.exists():
        raise StructureError(f"{path}: no such file")
    if path.is_dir():
        raise StructureError(f"{path}: is a directory, not a structure file")
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise StructureError(f"{path}: cannot read ({exc.strerror})") from None
    if data[:2] == b"\x1f\x8b":
        try:
            data = gzip.decompress(data)
        except (OSError, EOFError, zlib.error) as exc:
            raise StructureError(f"{path}: corrupt gzip file ({exc})") from None
    if not data.strip():
        raise StructureError(f"{path}: empty file")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        return data.decode("latin-1")


def _looks_like_mmcif(text: str) -> bool:
    """True when the first line that is neither blank nor a comment starts a CIF block."""
    for line in text.splitlines():
        stripped = line.strip()
        if stripped and not stripped.startswith("#"):
            return stripped.lower().startswith("data_")
    return False


def _parse(text: str, fmt: str, path: Path) -> gemmi.Structure:
    """gemmi.Structure of ``text`` with entities set up and ``name`` set to the entry id."""
    try:
        if fmt == "mmcif":
            st = gemmi.make_structure_from_block(gemmi.cif.read_string(text)[0])
        else:
            st = gemmi.read_pdb_string(text)
    except (RuntimeError, ValueError, IndexError) as exc:
        kind = "mmCIF" if fmt == "mmcif" else "PDB"
        raise StructureError(f"{path}: not a readable {kind} file ({exc})") from None
    if len(st) == 0:
        raise StructureError(f"{path}: not a structure file (no atoms found)")
    st.setup_entities()
    st.name = _info(st, "_entry.id") or path.name.split(".")[0]
    return st


def _info(st: gemmi.Structure, key: str) -> str:
    return st.info[key] if key in st.info else ""


@dataclass
class _Atoms:
    """Flat arrays from one pass over a gemmi model; one entry per gemmi residue."""

    coords: np.ndarray  # (n_atoms, 3)
    chain: list[str]
    chain_part: np.ndarray  # ordinal of the gemmi chain (a chain id may have several parts)
    seq: np.ndarray
    icode: list[str]
    resname: list[str]
    protein: np.ndarray  # bool
    start: np.ndarray
    stop: np.ndarray
    backbone: np.ndarray  # (n_res, 4) rows of coords for N, CA, C, O, -1 if missing
    nucleic: np.ndarray  # bool, polymer nucleotide
    water: np.ndarray  # bool
    atom_name: list[str]  # per atom from here on
    element: list[str]
    altloc: list[str]
    b_factor: list[float]
    occupancy: list[float]
    n_hetero: int
    n_water: int
    n_altloc: int


def _scan_model(model: gemmi.Model) -> _Atoms:
    """Walk the model once (chain, residue, atom) and collect everything needed."""
    xyz: list[tuple[float, float, float]] = []
    chain, part, seq, icode, resname, protein, start, stop, backbone = ([] for _ in range(9))
    nucleic, water, atom_name, element, altloc, b_factor, occupancy = ([] for _ in range(7))
    n_hetero = n_water = n_altloc = 0
    amino_acid: dict[str, bool] = {}
    nucleotide: dict[str, bool] = {}
    for k, ch in enumerate(model):
        peptide_chain = ch.get_polymer().check_polymer_type() in _PEPTIDE
        for res in ch:
            first = len(xyz)
            bb = [-1, -1, -1, -1]
            conformer = ""
            for atom in res:
                p = atom.pos
                xyz.append((p.x, p.y, p.z))
                alt = atom.altloc if atom.has_altloc() else ""
                atom_name.append(atom.name)
                element.append(atom.element.name)
                altloc.append(alt)
                b_factor.append(atom.b_iso)
                occupancy.append(atom.occ)
                n_altloc += alt != ""
                conformer = conformer or alt
                if atom.name in _BACKBONE and alt in ("", conformer):
                    slot = _BACKBONE.index(atom.name)
                    if bb[slot] < 0:
                        bb[slot] = len(xyz) - 1
            if res.is_water():
                n_water += len(res)
            elif res.het_flag == "H":
                n_hetero += len(res)
            if res.name not in amino_acid:
                tabulated = gemmi.find_tabulated_residue(res.name)
                amino_acid[res.name] = tabulated.is_amino_acid()
                nucleotide[res.name] = tabulated.is_nucleic_acid()
            polymer = res.entity_type == gemmi.EntityType.Polymer
            nucleic.append(polymer and nucleotide[res.name])
            water.append(res.is_water())
            chain.append(ch.name)
            part.append(k)
            seq.append(res.seqid.num)
            icode.append(res.seqid.icode.strip())
            resname.append(res.name)
            protein.append(polymer and (peptide_chain or amino_acid[res.name]))
            start.append(first)
            stop.append(len(xyz))
            backbone.append(bb)
    return _Atoms(
        coords=np.array(xyz, dtype=np.float64).reshape(-1, 3),
        chain=chain,
        chain_part=np.array(part, dtype=np.int64),
        seq=np.array(seq, dtype=np.int64),
        icode=icode,
        resname=resname,
        protein=np.array(protein, dtype=bool),
        start=np.array(start, dtype=np.int64),
        stop=np.array(stop, dtype=np.int64),
        backbone=np.array(backbone, dtype=np.int64).reshape(-1, 4),
        nucleic=np.array(nucleic, dtype=bool),
        water=np.array(water, dtype=bool),
        atom_name=atom_name,
        element=element,
        altloc=altloc,
        b_factor=b_factor,
        occupancy=occupancy,
        n_hetero=n_hetero,
        n_water=n_water,
        n_altloc=n_altloc,
    )


@dataclass
class _Groups:
    """Residues as the user sees them: consecutive gemmi residues sharing chain and
    sequence id (residue-level alternate conformations) form one group."""

    first: np.ndarray  # gemmi residue giving the label and backbone
    start: np.ndarray  # atom range of the whole group
    stop: np.ndarray


def _residue_groups(atoms: _Atoms) -> _Groups:
    icode = np.array(atoms.icode, dtype=object)
    same = np.zeros(len(atoms.seq), dtype=bool)
    same[1:] = (
        (atoms.chain_part[1:] == atoms.chain_part[:-1])
        & (atoms.seq[1:] == atoms.seq[:-1])
        & (icode[1:] == icode[:-1])
    )
    first = np.flatnonzero(~same)
    last = np.append(first[1:], len(same)) - 1
    return _Groups(first=first, start=atoms.start[first], stop=atoms.stop[last])


def _backbone_runs(atoms: _Atoms, groups: _Groups, notes: list[str]) -> list[np.ndarray]:
    """Group indices of each backbone segment (protein residues with Cα, no gap > MAX_CA_STEP)."""
    res = groups.first
    protein = atoms.protein[res]
    has_ca = atoms.backbone[res, 1] >= 0
    for g in np.flatnonzero(protein & ~has_ca):
        notes.append(f"residue {_label(atoms, res[g])} has no CA atom: skipped")
    candidates = np.flatnonzero(protein & has_ca)
    ca = atoms.coords[atoms.backbone[res[candidates], 1]]
    cut = np.ones(len(candidates), dtype=bool)
    cut[1:] = (atoms.chain_part[res[candidates[1:]]] != atoms.chain_part[res[candidates[:-1]]]) | (
        np.linalg.norm(np.diff(ca, axis=0), axis=1) > MAX_CA_STEP
    )
    runs = []
    for run in np.split(candidates, np.flatnonzero(cut)[1:]):
        if len(run) >= 2:
            runs.append(run)
        elif len(run) == 1:
            notes.append(
                f"residue {_label(atoms, res[run[0]])} has no bonded neighbour: not in any segment"
            )
    return runs


def _label(atoms: _Atoms, r: int) -> str:
    return f"{atoms.chain[r]}:{atoms.resname[r]}{atoms.seq[r]}{atoms.icode[r]}"


def _backbone_xyz(atoms: _Atoms, residues: np.ndarray) -> np.ndarray:
    """(len(residues), 4, 3) N, CA, C, O coordinates, NaN where missing."""
    rows = atoms.backbone[residues]
    xyz = atoms.coords[rows.clip(min=0)]
    xyz[rows < 0] = np.nan
    return xyz


def _secondary_structure(
    st: gemmi.Structure,
    fmt: str,
    atoms: _Atoms,
    groups: _Groups,
    runs: list[np.ndarray],
    notes: list[str],
) -> tuple[np.ndarray, str]:
    """'H'/'E'/'C' per backbone residue (concatenated runs) and where it came from."""
    rows = np.concatenate(runs)
    if len(st.helices) or len(st.sheets):
        ss = _ss_from_records(st, atoms, groups, notes)[rows]
        return ss, SS_FROM_MMCIF if fmt == "mmcif" else SS_FROM_PDB_RECORDS
    res = groups.first[rows]
    xyz = _backbone_xyz(atoms, res)
    chain_start = np.zeros(len(rows), dtype=bool)
    chain_start[np.cumsum([0] + [len(r) for r in runs[:-1]])] = True
    proline = np.array([atoms.resname[r] == "PRO" for r in res])
    if not np.isfinite(xyz[:, [0, 2, 3]]).any():
        notes.append("no backbone N, C or O atoms: secondary structure cannot be computed (all coil)")
    ss = dssp(
        xyz[:, 0],
        xyz[:, 1],
        xyz[:, 2],
        xyz[:, 3],
        chain_start=chain_start,
        proline=proline,
        helix_caps=True,
    )
    return ss, SS_COMPUTED


def _ss_from_records(
    st: gemmi.Structure, atoms: _Atoms, groups: _Groups, notes: list[str]
) -> np.ndarray:
    """'H'/'E'/'C' per residue group from the helix and sheet records (helix wins)."""
    res = groups.first
    where = {(atoms.chain[r], atoms.seq[r], atoms.icode[r]): g for g, r in enumerate(res.tolist())}
    chain = np.array([atoms.chain[r] for r in res], dtype=object)
    ss = np.full(len(res), "C", dtype="<U1")
    strands = [(s.start, s.end, "sheet strand") for sheet in st.sheets for s in sheet.strands]
    helices = [(h.start, h.end, "helix") for h in st.helices]
    for begin, end, what in strands + helices:
        keys = [(a.chain_name, a.res_id.seqid.num, a.res_id.seqid.icode.strip()) for a in (begin, end)]
        first, last = where.get(keys[0]), where.get(keys[1])
        if first is None or last is None or last < first:
            notes.append(
                f"{what} record {begin.chain_name}:{begin.res_id}-{end.res_id} "
                "does not match the model: ignored"
            )
            continue
        span = np.arange(first, last + 1)
        ss[span[chain[span] == keys[0][0]]] = "H" if what == "helix" else "E"
    return ss


def _make_segments(
    atoms: _Atoms, groups: _Groups, runs: list[np.ndarray], ss: np.ndarray
) -> tuple[BackboneSegment, ...]:
    segments = []
    offset = 0
    for run in runs:
        res = groups.first[run]
        xyz = _backbone_xyz(atoms, res)
        count = len(run)
        segments.append(
            BackboneSegment(
                chain=atoms.chain[res[0]],
                resseq=_frozen(atoms.seq[res]),
                icode=_frozen(np.array([atoms.icode[r] for r in res], dtype="<U1")),
                resname=_frozen(np.array([atoms.resname[r] for r in res], dtype=str)),
                ss=_frozen(ss[offset : offset + count]),
                n=_frozen(xyz[:, 0]),
                ca=_frozen(xyz[:, 1]),
                c=_frozen(xyz[:, 2]),
                o=_frozen(xyz[:, 3]),
                residue_index=_frozen(np.arange(offset, offset + count, dtype=np.int64)),
                atom_start=_frozen(groups.start[run]),
                atom_stop=_frozen(groups.stop[run]),
            )
        )
        offset += count
    return tuple(segments)


def _atom_residue(n_atoms: int, groups: _Groups, rows: np.ndarray) -> np.ndarray:
    """(n_atoms,) residue-table row of each atom, -1 outside the segments."""
    start, stop = groups.start[rows], groups.stop[rows]
    counts = stop - start
    first_of_each = np.repeat(start - np.cumsum(counts) + counts, counts)
    owner = np.full(n_atoms, -1, dtype=np.int64)
    owner[first_of_each + np.arange(counts.sum())] = np.repeat(np.arange(len(rows)), counts)
    return owner


def _chain_summaries(atoms: _Atoms, segments: tuple[BackboneSegment, ...]) -> tuple[ChainSummary, ...]:
    names = list(dict.fromkeys(atoms.chain))
    return tuple(
        ChainSummary(
            name=name,
            n_residues=atoms.chain.count(name),
            n_backbone=sum(len(s) for s in segments if s.chain == name),
            n_segments=sum(1 for s in segments if s.chain == name),
        )
        for name in names
    )


def _frozen(array: np.ndarray) -> np.ndarray:
    array = np.ascontiguousarray(array)
    array.flags.writeable = False
    return array


# ----------------------------------------------------------------------------- writing


def write_structure(
    structure: Structure,
    coords: NDArray[np.float64],
    path: str | os.PathLike[str],
    *,
    overwrite: bool = False,
) -> Path:
    """Write ``structure`` with its first-model atoms moved to ``coords``.

    Everything else is kept: header records, SEQRES, HELIX/SHEET, SSBOND/LINK, CONECT,
    hetero groups, waters, B-factors, occupancies, altlocs, numbering (auth and label
    ids in mmCIF) and the other models of a multi-model entry (unchanged). Anisotropic
    displacement parameters are written as read (not rotated with moved residues).
    mmCIF input written as mmCIF keeps every category of the input; only the atom
    records are regenerated.

    Parameters
    ----------
    structure : Structure
    coords : (structure.n_atoms, 3) float array, Å
        New positions in the order of ``structure.coords``.
    path : str or path-like
        Output file; the format follows the extension: .pdb/.ent (PDB) or .cif/.mmcif
        (mmCIF), optionally followed by .gz.
    overwrite : bool
        Allow replacing an existing file, including the input file.

    Returns
    -------
    Path
        The file written. The write is atomic (temporary file, then rename).

    Raises
    ------
    StructureError
        Wrong shape or non-finite ``coords``, unknown extension, or content the target
        format cannot hold (e.g. chain ids longer than 2 characters in PDB).
    FileExistsError
        ``path`` exists and ``overwrite`` is False.
    """
    path = Path(path)
    coords = _checked_coords(structure, coords)
    fmt, compress = _output_format(path)
    if not overwrite and path.exists():
        same = structure.path.exists() and path.samefile(structure.path)
        raise FileExistsError(
            f"{path}: refusing to overwrite {'the input file' if same else 'an existing file'}"
        )
    st = structure._template.clone()
    _set_positions(st[0], coords)
    try:
        text = _pdb_text(st, structure) if fmt == "pdb" else _mmcif_text(st, structure)
    except RuntimeError as exc:
        raise StructureError(f"{path}: cannot write {fmt.upper()} ({exc})") from None
    data = text.encode()
    _atomic_write(path, gzip.compress(data, mtime=0) if compress else data)
    return path


def _checked_coords(structure: Structure, coords: NDArray[np.float64]) -> np.ndarray:
    coords = np.asarray(coords, dtype=np.float64)
    if coords.shape != structure.coords.shape:
        raise StructureError(f"coords must have shape {structure.coords.shape}; got {coords.shape}")
    if not np.isfinite(coords).all():
        raise StructureError(f"coords contains {int((~np.isfinite(coords)).sum())} non-finite value(s)")
    return coords


def _output_format(path: Path) -> tuple[str, bool]:
    """('pdb' | 'mmcif', gzip?) from the file name."""
    name = path.name.lower()
    compress = name.endswith(".gz")
    stem = name.removesuffix(".gz")
    if stem.endswith(_PDB_SUFFIXES):
        return "pdb", compress
    if stem.endswith(_MMCIF_SUFFIXES):
        return "mmcif", compress
    raise StructureError(f"{path}: unknown extension; use .pdb, .ent, .cif or .mmcif (optionally + .gz)")


def _set_positions(model: gemmi.Model, coords: np.ndarray) -> None:
    rows = iter(np.round(coords, 3).tolist())
    for ch in model:
        for res in ch:
            for atom in res:
                atom.pos = gemmi.Position(*next(rows))


def _pdb_text(st: gemmi.Structure, structure: Structure) -> str:
    options = gemmi.PdbWriteOptions()
    options.preserve_serial = True
    options.conect_records = True
    text = st.make_pdb_string(options)
    if structure.source_format == "pdb":
        text = _with_input_header(text, structure._text)
    return text


def _with_input_header(written: str, original: str) -> str:
    """Insert into gemmi's PDB output the header records of the input of a type gemmi did
    not write (COMPND, SOURCE, AUTHOR, REVDAT, JRNL, FORMUL, SITE, ...), in standard order."""
    rank = {record: k for k, record in enumerate(_PDB_HEADER_ORDER)}
    lines = written.splitlines()
    n_header = next(
        (k for k, line in enumerate(lines) if _record(line) in _COORDINATE_RECORDS), len(lines)
    )
    present = {_record(line) for line in lines}
    extra = []
    for line in original.splitlines():
        record = _record(line)
        if record in _COORDINATE_RECORDS:
            break
        if record in rank and record not in present:
            extra.append(line.rstrip("\r"))
    if not extra:
        return written
    keyed = []
    last = 0
    for line in lines[:n_header]:
        last = rank.get(_record(line), last)
        keyed.append((last, line))
    keyed += [(rank[_record(line)], line) for line in extra]
    header = [line for _, line in sorted(keyed, key=lambda item: item[0])]
    return "\n".join(header + lines[n_header:]) + "\n"


def _record(line: str) -> str:
    return line[:6].strip()


def _mmcif_text(st: gemmi.Structure, structure: Structure) -> str:
    if structure.source_format != "mmcif":
        return st.make_mmcif_document().as_string()
    doc = gemmi.cif.read_string(structure._text)
    groups = gemmi.MmcifOutputGroups(False, atoms=True, group_pdb=True, auth_all=True)
    st.update_mmcif_block(doc[0], groups)
    return doc.as_string()


def _atomic_write(path: Path, data: bytes) -> None:
    """Write ``data`` to a temporary file next to ``path``, then rename it onto ``path``."""
    mode = path.stat().st_mode & 0o777 if path.exists() else 0o644
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as out:
            out.write(data)
            out.flush()
            os.fsync(out.fileno())
        os.chmod(tmp, mode)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise
