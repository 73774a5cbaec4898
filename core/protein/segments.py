"""From the scanned atoms of a model to what a :class:`Structure` holds of its protein:
residues as the user sees them, continuous backbone segments, their secondary structure
(the file's records, or computed), and per-chain counts."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import gemmi
import numpy as np

from core.protein.secondary_structure import dssp
from core.protein.structure import (
    MAX_CA_STEP,
    SS_COMPUTED,
    SS_FROM_MMCIF,
    SS_FROM_PDB_RECORDS,
    BackboneSegment,
    ChainSummary,
    amino_acid_letter,
    frozen,
)

if TYPE_CHECKING:
    from core.protein.scanning import ScannedModel


@dataclass
class Groups:
    """Residues as the user sees them: consecutive gemmi residues sharing chain and
    sequence id (residue-level alternate conformations) form one group."""

    first: np.ndarray  # gemmi residue giving the label and backbone
    start: np.ndarray  # atom range of the whole group
    stop: np.ndarray


def residue_groups(atoms: ScannedModel) -> Groups:
    icode = np.array(atoms.icode, dtype=object)
    same = np.zeros(len(atoms.seq), dtype=bool)
    same[1:] = (
        (atoms.chain_part[1:] == atoms.chain_part[:-1])
        & (atoms.seq[1:] == atoms.seq[:-1])
        & (icode[1:] == icode[:-1])
    )
    first = np.flatnonzero(~same)
    last = np.append(first[1:], len(same)) - 1
    return Groups(first=first, start=atoms.start[first], stop=atoms.stop[last])


def backbone_runs(atoms: ScannedModel, groups: Groups, notes: list[str]) -> list[np.ndarray]:
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


def _label(atoms: ScannedModel, r: int) -> str:
    return f"{atoms.chain[r]}:{atoms.resname[r]}{atoms.seq[r]}{atoms.icode[r]}"


def _backbone_xyz(atoms: ScannedModel, residues: np.ndarray) -> np.ndarray:
    """(len(residues), 4, 3) N, CA, C, O coordinates, NaN where missing."""
    rows = atoms.backbone[residues]
    xyz = atoms.coords[rows.clip(min=0)]
    xyz[rows < 0] = np.nan
    return xyz


def secondary_structure(
    st: gemmi.Structure,
    fmt: str,
    atoms: ScannedModel,
    groups: Groups,
    runs: list[np.ndarray],
    notes: list[str],
) -> tuple[np.ndarray, str]:
    """'H'/'E'/'C' per backbone residue (concatenated runs) and where it came from."""
    rows = np.concatenate(runs)
    if len(st.helices) or any(len(sheet.strands) for sheet in st.sheets):
        unmatched: list[str] = []
        ss, matched = _ss_from_records(st, atoms, groups, unmatched)
        if matched:
            notes.extend(unmatched)
            return ss[rows], SS_FROM_MMCIF if fmt == "mmcif" else SS_FROM_PDB_RECORDS
        notes.append(f"none of the file's {len(unmatched)} helix and sheet records matches a residue of the "
                     "model (renumbered after they were written?): secondary structure computed instead")
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
    st: gemmi.Structure, atoms: ScannedModel, groups: Groups, notes: list[str]
) -> tuple[np.ndarray, int]:
    """'H'/'E'/'C' per residue group from the helix and sheet records (helix wins), and how
    many records matched the model; a note for each that did not."""
    res = groups.first
    where = {(atoms.chain[r], atoms.seq[r], atoms.icode[r]): g for g, r in enumerate(res.tolist())}
    chain = np.array([atoms.chain[r] for r in res], dtype=object)
    ss = np.full(len(res), "C", dtype="<U1")
    matched = 0
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
        matched += 1
    return ss, matched


def make_segments(
    atoms: ScannedModel, groups: Groups, runs: list[np.ndarray], ss: np.ndarray
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
                resseq=frozen(atoms.seq[res]),
                icode=frozen(np.array([atoms.icode[r] for r in res], dtype="<U1")),
                resname=frozen(np.array([atoms.resname[r] for r in res], dtype=str)),
                ss=frozen(ss[offset : offset + count]),
                n=frozen(xyz[:, 0]),
                ca=frozen(xyz[:, 1]),
                c=frozen(xyz[:, 2]),
                o=frozen(xyz[:, 3]),
                residue_index=frozen(np.arange(offset, offset + count, dtype=np.int64)),
                atom_start=frozen(groups.start[run]),
                atom_stop=frozen(groups.stop[run]),
                sequence="".join(amino_acid_letter(atoms.resname[r], atoms.parents) for r in res),
            )
        )
        offset += count
    return tuple(segments)


def atom_residue(n_atoms: int, groups: Groups, rows: np.ndarray) -> np.ndarray:
    """(n_atoms,) residue-table row of each atom, -1 outside the segments."""
    start, stop = groups.start[rows], groups.stop[rows]
    counts = stop - start
    first_of_each = np.repeat(start - np.cumsum(counts) + counts, counts)
    owner = np.full(n_atoms, -1, dtype=np.int64)
    owner[first_of_each + np.arange(counts.sum())] = np.repeat(np.arange(len(rows)), counts)
    return owner


def chain_summaries(atoms: ScannedModel, segments: tuple[BackboneSegment, ...]) -> tuple[ChainSummary, ...]:
    names = list(dict.fromkeys(atoms.chain))
    nucleotides: dict[str, list[str]] = {name: [] for name in names}
    for name, resname, nucleic in zip(atoms.chain, atoms.resname, atoms.nucleic, strict=True):
        if nucleic:
            nucleotides[name].append(resname)
    return tuple(
        ChainSummary(
            name=name,
            n_residues=atoms.chain.count(name),
            n_backbone=sum(len(s) for s in segments if s.chain == name),
            n_segments=sum(1 for s in segments if s.chain == name),
            n_nucleotides=len(nucleotides[name]),
            nucleic_acid=_nucleic_acid_kind(nucleotides[name], atoms.parents),
        )
        for name in names
    )


def _nucleic_acid_kind(resnames: list[str], parents: dict[str, str]) -> str:
    """'DNA', 'RNA' or 'DNA/RNA' by the kinds of nucleotide names gemmi tabulates (DA is DNA,
    A and PSU are RNA), a modified one gemmi lacks by its parent's (``parents``); '' where
    none of the names is of a known kind."""
    kinds = set()
    for name in set(resnames):
        tabulated = gemmi.find_tabulated_residue(name)
        if tabulated is not None and not tabulated.is_nucleic_acid() and name in parents:
            tabulated = gemmi.find_tabulated_residue(parents[name])
        if tabulated is not None and tabulated.kind in (gemmi.ResidueKind.DNA, gemmi.ResidueKind.RNA):
            kinds.add("DNA" if tabulated.kind == gemmi.ResidueKind.DNA else "RNA")
    return "/".join(sorted(kinds))
