"""Biological assemblies: the copies of a file's chains that its assembly records
(PDB REMARK 350, mmCIF ``_pdbx_struct_assembly``) generate, built by gemmi's
``make_assembly`` and written as a new mmCIF text that opens like any file.

A copied chain is named after its chain and the number of its copy (``A1``, ``A2``, ...);
each copy keeps the helix and sheet records of its chain, so an assembly is drawn with the
secondary structure its file gives, not one computed again.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import gemmi

from core.protein.input_files import StructureError, read_bytes
from core.protein.reading import parse_model


@dataclass(frozen=True)
class Assembly:
    """One biological assembly of a file, numbered from 1 in file order."""

    number: int
    name: str
    """The file's name for it (``'1'``, ``'PAU'``...)."""
    chains: int
    atoms: int
    details: str
    """How the file describes it (``'author_and_software_defined_assembly'``...), or ''."""

    def describe(self) -> str:
        """E.g. ``'assembly 1: 60 chains, 95,280 atoms'``."""
        chains = "1 chain" if self.chains == 1 else f"{self.chains} chains"
        return f"assembly {self.number}: {chains}, {self.atoms:,} atoms"


def assemblies(path: str | os.PathLike[str], data: bytes | None = None, *, model: int = 1) -> list[Assembly]:
    """The biological assemblies of ``path`` (its content ``data`` if already read), built from model ``model``."""
    st, chosen = _parsed(Path(path), data, model)
    built = [_build(st, chosen, assembly) for assembly in st.assemblies]
    return [Assembly(k, a.name, len({c.name for c in m if c.get_polymer()}), m.count_atom_sites(),
                     a.oligomeric_details or "")
            for k, (a, m) in enumerate(zip(st.assemblies, built, strict=True), start=1)]


def assembly_path(path: str | os.PathLike[str], number: int) -> Path:
    """The name an assembly of ``path`` goes by, beside it: ``2BUK.pdb.gz`` -> ``2BUK-assembly1.cif``."""
    path = Path(path)
    return path.with_name(f"{path.name.split('.')[0]}-assembly{number}.cif")


def assembly_text(path: str | os.PathLike[str], data: bytes | None = None, *, number: int = 1,
                  model: int = 1) -> str:
    """Assembly ``number`` (from 1) of model ``model`` of ``path`` as an mmCIF text (raises
    StructureError for a file without that assembly)."""
    path = Path(path)
    st, chosen = _parsed(path, data, model)
    if isinstance(number, bool) or not isinstance(number, int) or not 1 <= number <= len(st.assemblies):
        have = f"assemblies 1 to {len(st.assemblies)}" if st.assemblies else "no assembly records"
        raise StructureError(f"{path}: no assembly {number!r}; the file has {have}")
    copies = _build(st, chosen, st.assemblies[number - 1])
    built = gemmi.Structure()
    built.name, built.cell, built.spacegroup_hm = st.name, st.cell, st.spacegroup_hm
    for key in ("_struct.title", "_struct_keywords.pdbx_keywords", "_exptl.method"):
        if key in st.info:
            built.info[key] = st.info[key]
    built.add_model(copies)
    _copy_secondary_structure(st, built, _copy_names(chosen, copies))
    built.setup_entities()
    return built.make_mmcif_document().as_string()


def _parsed(path: Path, data: bytes | None, model: int) -> tuple[gemmi.Structure, gemmi.Model]:
    st = parse_model(path, read_bytes(path) if data is None else data, model)
    st.setup_entities()  # (the subchains that mmCIF generators name)
    return st, st[model - 1]


def _build(st: gemmi.Structure, model: gemmi.Model, assembly: gemmi.Assembly) -> gemmi.Model:
    try:
        return gemmi.make_assembly(assembly, model, gemmi.HowToNameCopiedChain.AddNumber)
    except (RuntimeError, ValueError) as error:
        raise StructureError(f"{st.name}: cannot build assembly {assembly.name!r} ({error})") from None


def _copy_names(model: gemmi.Model, copies: gemmi.Model) -> dict[str, list[str]]:
    """The names of the copies of each chain of ``model`` (``{'A': ['A1', 'A2']}``)."""
    originals = sorted({chain.name for chain in model}, key=len, reverse=True)  # 'A1' before 'A'
    names: dict[str, list[str]] = {}
    for chain in copies:
        original = next((o for o in originals if chain.name.startswith(o) and chain.name[len(o):].isdigit()), None)
        if original is not None and chain.name not in names.get(original, []):
            names.setdefault(original, []).append(chain.name)
    return names


def _copy_secondary_structure(st: gemmi.Structure, built: gemmi.Structure, names: dict[str, list[str]]) -> None:
    """Each helix and sheet of ``st``, once for every copy of its chain in ``built``."""
    def moved(address: gemmi.AtomAddress, chain: str) -> gemmi.AtomAddress:
        return gemmi.AtomAddress(chain, address.res_id.seqid, address.res_id.name, address.atom_name,
                                 address.altloc)

    for helix in st.helices:
        for chain in names.get(helix.start.chain_name, []):
            copy = gemmi.Helix()
            copy.start, copy.end = moved(helix.start, chain), moved(helix.end, chain)
            copy.pdb_helix_class, copy.length = helix.pdb_helix_class, helix.length
            built.helices.append(copy)
    for sheet in st.sheets:
        chains = {strand.start.chain_name for strand in sheet.strands}
        for k in range(max((len(names.get(chain, [])) for chain in chains), default=0)):
            copy = gemmi.Sheet(f"{sheet.name}_{k + 1}")
            for strand in sheet.strands:
                copies = names.get(strand.start.chain_name, [])
                if k < len(copies):
                    piece = gemmi.Sheet.Strand()
                    piece.start, piece.end = moved(strand.start, copies[k]), moved(strand.end, copies[k])
                    piece.sense = strand.sense
                    copy.strands.append(piece)
            built.sheets.append(copy)
