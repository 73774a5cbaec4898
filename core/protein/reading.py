"""Reading PDB and mmCIF files (optionally gzipped) with gemmi into a :class:`Structure`.

:func:`read_structure` returns the first model's atoms plus the protein backbone cut into
continuous segments (:mod:`core.protein.segments`); :func:`read_atoms` returns just the
:class:`AtomTable` of any entry (DNA without protein included), for surfaces and maps.
The format is taken from the content, not the name. The gemmi objects stay private
inside ``Structure``.
"""

from __future__ import annotations

import os
from pathlib import Path

import gemmi
import numpy as np

from core.protein.input_files import StructureError, looks_like_mmcif, read_bytes, text_of
from core.protein.parsing import info, parse
from core.protein.scanning import ScannedModel, modified_parents, scan_model
from core.protein.segments import (
    atom_residue,
    backbone_runs,
    chain_summaries,
    make_segments,
    residue_groups,
    secondary_structure,
)  # fmt: skip
from core.protein.structure import AtomTable, Structure, frozen


def read_structure(
    path: str | os.PathLike[str], data: bytes | None = None, *, model: int = 1, require_protein: bool = True
) -> Structure:
    """Read one model of a PDB or mmCIF file (optionally gzipped); the format is taken from the content.

    Parameters
    ----------
    path : str or path-like
    data : the file's content (as :func:`read_bytes` gives it) if already read; ``path`` then
        only names it, and need not exist.
    model : which model, 1 .. ``n_models`` in file order (default the first).
    require_protein : refuse an entry without a protein chain (else it reads with no
        segments, e.g. DNA to look at).

    Returns
    -------
    Structure

    Raises
    ------
    StructureError
        Missing, empty or unreadable file, no such model, no atoms, no protein chain (if
        required), or non-finite coordinates; the message names the file.
    """
    path = Path(path)
    text, encoding, fmt, st, atoms = _read_model(path, read_bytes(path) if data is None else data, model)
    notes: list[str] = []
    groups = residue_groups(atoms)
    runs = backbone_runs(atoms, groups, notes)
    if not runs and require_protein:
        raise StructureError(
            f"{path}: no protein chain (no two consecutive amino-acid residues with Cα)"
        )
    rows = np.concatenate(runs) if runs else np.empty(0, dtype=np.int64)
    ss, ss_source = secondary_structure(st, fmt, atoms, groups, runs, notes) if runs else (np.empty(0, str), "")
    segments = make_segments(atoms, groups, runs, ss)
    return Structure(
        path=path,
        source_format=fmt,
        entry_id=st.name,
        title=info(st, "_struct.title"),
        method="; ".join(dict.fromkeys(experiment.method for experiment in st.meta.experiments if experiment.method)),
        resolution=float(st.resolution) if st.resolution > 0 else None,
        coords=frozen(atoms.coords),
        atom_residue=frozen(atom_residue(len(atoms.coords), groups, rows)),
        segments=segments,
        ss_source=ss_source,
        chains=chain_summaries(atoms, segments),
        n_models=len(st),
        model_number=int(model),
        n_hetero_atoms=atoms.n_hetero,
        n_water_atoms=atoms.n_water,
        n_altloc_atoms=atoms.n_altloc,
        warnings=tuple(notes),
        atoms=_atom_table(st.name, atoms),
        _template=st,
        _text=text,
        _encoding=encoding,
    )


def read_atoms(path: str | os.PathLike[str], model: int = 1) -> AtomTable:
    """Read every atom of one model (1 .. n, default the first) of a PDB or mmCIF file (optionally gzipped).

    Unlike :func:`read_structure` this needs no protein chain (e.g. a DNA duplex).

    Raises
    ------
    StructureError
        Missing, empty or unreadable file, no such model, no atoms, or non-finite coordinates.
    """
    path = Path(path)
    _, _, _, st, atoms = _read_model(path, read_bytes(path), model)
    return _atom_table(st.name, atoms)


def parse_model(path: str | os.PathLike[str], data: bytes, model: int = 1) -> gemmi.Structure:
    """The file's content ``data`` parsed by gemmi, which has model ``model`` (from 1; else StructureError)."""
    return _parsed(Path(path), data, model)[3]


def _parsed(path: Path, data: bytes, model: int) -> tuple[str, str, str, gemmi.Structure]:
    """Text, its encoding, format and parsed structure of a file that has model ``model`` (from 1)."""
    text, encoding = text_of(path, data)
    fmt = "mmcif" if looks_like_mmcif(text) else "pdb"
    if fmt == "pdb":
        _check_coordinate_fields(text, path)
    st = parse(text, fmt, path)
    if isinstance(model, bool) or not isinstance(model, (int, np.integer)) or not 1 <= model <= len(st):
        raise StructureError(f"{path}: no model {model!r}; the file has {len(st)} model(s), "
                             f"numbered 1 to {len(st)} in file order")
    return text, encoding, fmt, st


def _read_model(path: Path, data: bytes, model: int) -> tuple[str, str, str, gemmi.Structure, ScannedModel]:
    """Text, its encoding, format, parsed structure and scanned model ``model`` (from 1) of a
    file with finite atoms."""
    text, encoding, fmt, st = _parsed(path, data, model)
    try:
        atoms = scan_model(st[int(model) - 1], modified_parents(st))
    except (TypeError, ValueError, RuntimeError) as exc:  # e.g. a residue gemmi left without a number
        raise StructureError(f"{path}: cannot read the atoms ({exc})") from None
    if len(atoms.coords) == 0:
        raise StructureError(f"{path}: not a structure file (no atoms found)")
    if not np.isfinite(atoms.coords).all():
        bad = int((~np.isfinite(atoms.coords).all(axis=1)).sum())
        raise StructureError(f"{path}: {bad} atom(s) have non-finite coordinates")
    return text, encoding, fmt, st, atoms


def _atom_table(entry_id: str, atoms: ScannedModel) -> AtomTable:
    counts = atoms.stop - atoms.start

    def per_atom(values: object, dtype: type) -> np.ndarray:
        return frozen(np.repeat(np.asarray(values, dtype=dtype), counts))

    category = np.select(
        [atoms.water, atoms.protein, atoms.nucleic], ["water", "protein", "nucleic"], "ligand"
    )
    return AtomTable(
        entry_id=entry_id,
        coords=frozen(atoms.coords),
        name=frozen(np.array(atoms.atom_name, dtype=str).reshape(-1)),
        element=frozen(np.array(atoms.element, dtype=str).reshape(-1)),
        altloc=frozen(np.array(atoms.altloc, dtype="<U1").reshape(-1)),
        resname=per_atom(atoms.resname, str),
        chain=per_atom(atoms.chain, str),
        resseq=per_atom(atoms.seq, np.int64),
        residue=per_atom(np.arange(len(counts)), np.int64),
        b_factor=frozen(np.array(atoms.b_factor, dtype=np.float64)),
        occupancy=frozen(np.array(atoms.occupancy, dtype=np.float64)),
        category=per_atom(category, str),
        parents=atoms.parents,
    )


def _check_coordinate_fields(text: str, path: Path) -> None:
    """Refuse a PDB atom record whose x, y or z (columns 31-54) is not a number: gemmi would
    read it as 0.000, and every command would compute on an invented position."""
    for number, line in enumerate(text.splitlines(), start=1):
        if line.startswith(("ATOM  ", "HETATM")):
            for start, axis in ((30, "x"), (38, "y"), (46, "z")):
                field = line[start : start + 8]
                try:
                    float(field)
                except ValueError:
                    raise StructureError(f"{path}: line {number}: the {axis} coordinate {field.strip()!r} "
                                         f"(columns {start + 1}-{start + 8}) is not a number") from None
