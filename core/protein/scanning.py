"""One pass over a gemmi model: its chains, residues and atoms as flat arrays
(:class:`ScannedModel`), from which :mod:`core.protein.reading` and
:mod:`core.protein.segments` build a :class:`~core.protein.structure.Structure`."""

from __future__ import annotations

from dataclasses import dataclass

import gemmi
import numpy as np

_BACKBONE = ("N", "CA", "C", "O")
_PEPTIDE = (gemmi.PolymerType.PeptideL, gemmi.PolymerType.PeptideD)
_NUCLEIC = (gemmi.PolymerType.Dna, gemmi.PolymerType.Rna, gemmi.PolymerType.DnaRnaHybrid)
_POLYMER_ELEMENTS = frozenset({"H", "D", "C", "N", "O", "S", "P", "Se"})
"""The elements of standard amino acids and nucleotides. A file without element columns
(CHARMM and NAMD write such) leaves gemmi to guess from names: CA as calcium, HG1 as mercury."""
_CHARMM_HISTIDINES = frozenset({"HSD", "HSE", "HSP"})
"""CHARMM's names of histidine by protonation, standard residues by another name."""


@dataclass
class ScannedModel:
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
    parents: dict[str, str]  # modified residue name -> its standard parent, as the file records it


def _element(atom: gemmi.Atom, standard: bool) -> str:
    """The atom's element; in a standard residue, the first letter of its name where the
    element gemmi gives is none of a standard residue's (a guess from a name, as above)."""
    name = atom.element.name
    if not standard or name in _POLYMER_ELEMENTS:
        return name
    letters = atom.name.lstrip("0123456789")  # 1HB, 2HG1: older PDB hydrogen names
    return letters[:1].upper() if letters[:1].upper() in _POLYMER_ELEMENTS else name


def scan_model(model: gemmi.Model, parents: dict[str, str]) -> ScannedModel:
    """Walk the model once (chain, residue, atom) and collect everything needed; ``parents``
    (see :func:`modified_parents`) is passed on."""
    xyz: list[tuple[float, float, float]] = []
    chain, part, seq, icode, resname, protein, start, stop, backbone = ([] for _ in range(9))
    nucleic, water, atom_name, element, altloc, b_factor, occupancy = ([] for _ in range(7))
    n_hetero = n_water = n_altloc = 0
    amino_acid: dict[str, bool] = {}
    nucleotide: dict[str, bool] = {}
    standard: dict[str, bool] = {}
    for k, ch in enumerate(model):
        polymer_type = ch.get_polymer().check_polymer_type()
        peptide_chain, nucleic_chain = polymer_type in _PEPTIDE, polymer_type in _NUCLEIC
        for res in ch:
            if res.name not in amino_acid:
                tabulated = gemmi.find_tabulated_residue(res.name)
                amino_acid[res.name] = tabulated.is_amino_acid()
                nucleotide[res.name] = tabulated.is_nucleic_acid()
                standard[res.name] = tabulated.is_standard() or res.name in _CHARMM_HISTIDINES
            first = len(xyz)
            bb = [-1, -1, -1, -1]
            conformer = ""
            for atom in res:
                p = atom.pos
                xyz.append((p.x, p.y, p.z))
                alt = atom.altloc if atom.has_altloc() else ""
                atom_name.append(atom.name)
                element.append(_element(atom, standard[res.name]))
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
            polymer = res.entity_type == gemmi.EntityType.Polymer
            nucleic.append(polymer and (nucleotide[res.name] or nucleic_chain and not amino_acid[res.name]))
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
    return ScannedModel(
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
        parents=parents,
    )


def modified_parents(st: gemmi.Structure) -> dict[str, str]:
    """The standard parent of each modified residue by name, from the file's PDB MODRES or
    mmCIF ``_pdbx_struct_mod_residue`` records: ``{'TCY': 'DA'}`` in 4OPJ."""
    return {m.res_id.name: m.parent_comp_id for m in st.mod_residues if m.parent_comp_id.strip()}
