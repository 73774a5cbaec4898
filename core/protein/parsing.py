"""A structure file's text parsed by gemmi as the whole project reads it: mmCIF author columns
filled where the file lacks them, entities set up, the structure named by its entry id (gemmi
alone, no numpy: the window's sketch of the molecule reads files with it before numpy loads)."""

from __future__ import annotations

from pathlib import Path

import gemmi

from core.protein.input_files import StructureError


def parse(text: str, fmt: str, path: Path) -> gemmi.Structure:
    """gemmi.Structure of ``text`` with entities set up and ``name`` set to the entry id."""
    try:
        if fmt == "mmcif":
            block = gemmi.cif.read_string(text)[0]
            _fill_author_columns(block)
            st = gemmi.make_structure_from_block(block)
        else:
            st = gemmi.read_pdb_string(text)
    except (RuntimeError, ValueError, IndexError) as exc:
        kind = "mmCIF" if fmt == "mmcif" else "PDB"
        raise StructureError(f"{path}: not a readable {kind} file ({exc})") from None
    if len(st) == 0:
        raise StructureError(f"{path}: not a structure file (no atoms found)")
    st.setup_entities()
    st.name = info(st, "_entry.id") or path.name.split(".")[0]
    return st


_LABEL_OF = {"auth_asym_id": "label_asym_id", "auth_comp_id": "label_comp_id", "auth_atom_id": "label_atom_id"}


def _fill_author_columns(block: gemmi.cif.Block) -> None:
    """Author columns of ``_atom_site`` that a file lacks, taken from its ``label_*`` columns
    (what the author numbering is, when there is none). A residue without ``label_seq_id``
    (ligands, waters) is numbered within its ``label_asym_id`` in file order: a new one starts
    where the chemical component changes or an atom name comes again."""
    tags = {tag.removeprefix("_atom_site.") for tag in block.find_mmcif_category("_atom_site.").tags}
    if not tags or all(tag in tags for tag in ("auth_seq_id", *_LABEL_OF)):
        return  # the usual file: nothing to fill
    table = block.get_mmcif_category("_atom_site.")
    for auth, label in _LABEL_OF.items():
        if auth not in table and label in table:
            table[auth] = list(table[label])
    if "auth_seq_id" not in table and "label_seq_id" in table:
        numbers, seen, previous, counter = [], set(), None, {}
        for asym, seq, comp, atom, alt in zip(table["label_asym_id"], table["label_seq_id"], table["label_comp_id"],
                                              table["label_atom_id"], table.get("label_alt_id") or
                                              [None] * len(table["label_seq_id"]), strict=True):
            if seq is not None and seq is not False:
                numbers.append(seq)
                continue
            key = (asym, comp)
            if key != previous or (atom, alt) in seen:
                counter[asym] = counter.get(asym, 0) + 1
                seen, previous = set(), key
            seen.add((atom, alt))
            numbers.append(str(counter[asym]))
        table["auth_seq_id"] = numbers
    block.set_mmcif_category("_atom_site.", table)


def info(st: gemmi.Structure, key: str) -> str:
    """The value of ``key`` (e.g. ``_struct.title``) in the file's metadata, or "" where it has none."""
    return st.info[key] if key in st.info else ""
