"""Writing edited coordinates back as PDB or mmCIF, keeping everything else of the input."""

from __future__ import annotations

import contextlib
import gzip
import os
import re
import tempfile
from collections.abc import Sequence
from pathlib import Path

import gemmi
import numpy as np
from numpy.typing import NDArray

from core.protein.input_files import StructureError
from core.protein.structure import Structure

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
_AS_READ = ("HET", "HETNAM", "HETSYN", "FORMUL")
"""PDB records written as the input has them (gemmi reorders them; no edit changes them)."""
_AS_READ_UNMOVED = ("SSBOND", "LINK", "CISPEP")
"""Records with distances and angles: the input's when nothing moved, else gemmi's, recomputed."""
PDB_COORDINATE_RANGE = (-999.9995, 9999.9995)
"""Å: what the ``%8.3f`` coordinate columns of PDB atom records can hold."""
PDB_VALUE_RANGE = (-99.995, 999.995)
"""What the ``%6.2f`` occupancy and B-factor columns can hold."""
_SAME_RANK = {"DBREF2": "DBREF1", "ORIGX2": "ORIGX1", "ORIGX3": "ORIGX1", "SCALE2": "SCALE1", "SCALE3": "SCALE1",
              "MTRIX2": "MTRIX1", "MTRIX3": "MTRIX1"}
# Records of several lines that alternate (an operator's three rows, a chain's two DBREF
# lines) rank as one record, so that the sort, which is stable, keeps them in the input order.



def write_structure(
    structure: Structure,
    coords: NDArray[np.float64],
    path: str | os.PathLike[str],
    *,
    overwrite: bool = False,
) -> Path:
    """Write ``structure`` with the atoms of its model moved to ``coords``.

    Everything else is kept: header records, SEQRES, HELIX/SHEET, SSBOND/LINK, CONECT,
    hetero groups, waters, B-factors, occupancies, altlocs, numbering (auth and label
    ids in mmCIF) and the other models of a multi-model entry (unchanged). Anisotropic
    displacement parameters are written as read (not rotated with moved residues).
    Written in its own format, a file changes only in the coordinates of the atoms that
    moved (and, in PDB, the SSBOND, LINK and CISPEP records whose distance or angle they
    change): every other byte, the other models' included, stays as read, and an unmoved
    structure is written byte for byte. Otherwise (or when the atom records are not laid
    out as read) gemmi writes the atoms; mmCIF input keeps every category of the input.

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
    fmt, compress = output_format(path)
    if fmt == "pdb":
        _check_pdb_columns(structure, coords, path)
    if not overwrite and path.exists():
        same = structure.path.exists() and path.samefile(structure.path)
        raise FileExistsError(
            f"{path}: refusing to overwrite {'the input file' if same else 'an existing file'}"
        )
    try:
        text = None
        if fmt == structure.source_format:
            text = (_patched_atom_site if fmt == "mmcif" else _patched_pdb)(structure, coords)
        if text is None:
            st = _moved(structure, coords)
            moved = not np.array_equal(coords, structure.coords)
            text = _pdb_text(st, structure, moved) if fmt == "pdb" else _mmcif_text(st, structure)
    except RuntimeError as exc:
        raise StructureError(f"{path}: cannot write {fmt.upper()} ({exc})") from None
    data = text.encode(structure._encoding)
    atomic_write(path, gzip.compress(data, mtime=0) if compress else data)
    return path


def write_models(
    structure: Structure,
    frames: Sequence[NDArray[np.float64]],
    path: str | os.PathLike[str],
    *,
    overwrite: bool = False,
) -> Path:
    """Write one model per frame (each ``(structure.n_atoms, 3)``, Å) of ``structure``'s
    model, numbered from 1: a multi-model PDB or mmCIF file that molecular viewers play as
    a movie. The header of the input is kept; the write is atomic. Raises as
    :func:`write_structure` does."""
    path = Path(path)
    fmt, compress = output_format(path)
    if not frames:
        raise StructureError(f"{path}: no frames to write")
    frames = [_checked_coords(structure, coords) for coords in frames]
    if fmt == "pdb":
        for coords in frames:
            _check_pdb_columns(structure, coords, path)
    if not overwrite and path.exists():
        raise FileExistsError(f"{path}: refusing to overwrite an existing file")
    st = structure._template.clone()
    template = st[structure.model_number - 1].clone()
    _set_elements(template, structure)
    for k in reversed(range(len(st))):
        del st[k]
    for number, coords in enumerate(frames, start=1):
        model = _moved_model(template, coords)
        model.num = number
        st.add_model(model)
    try:
        text = _pdb_text(st, structure, moved=True) if fmt == "pdb" else st.make_mmcif_document().as_string()
    except RuntimeError as exc:
        raise StructureError(f"{path}: cannot write {fmt.upper()} ({exc})") from None
    data = text.encode(structure._encoding)
    atomic_write(path, gzip.compress(data, mtime=0) if compress else data)
    return path


def _checked_coords(structure: Structure, coords: NDArray[np.float64]) -> np.ndarray:
    coords = np.asarray(coords, dtype=np.float64)
    if coords.shape != structure.coords.shape:
        raise StructureError(f"coords must have shape {structure.coords.shape}; got {coords.shape}")
    if not np.isfinite(coords).all():
        raise StructureError(f"coords contains {int((~np.isfinite(coords)).sum())} non-finite value(s)")
    return coords


def _check_pdb_columns(structure: Structure, coords: np.ndarray, path: Path) -> None:
    """Refuse values that the fixed columns of PDB atom records cannot hold (they would be
    written cut off or as other numbers)."""
    for name, values, (low, high), holds in (
        ("coordinate", coords, PDB_COORDINATE_RANGE, "-999.999 to 9999.999 Å"),
        ("B-factor", structure.atoms.b_factor, PDB_VALUE_RANGE, "-99.99 to 999.99"),
        ("occupancy", structure.atoms.occupancy, PDB_VALUE_RANGE, "-99.99 to 999.99"),
    ):
        rows = values.reshape(len(values), -1)  # (n, 3) coordinates or (n, 1) values
        outside = (rows < low) | (rows > high)
        bad = np.flatnonzero(outside.any(axis=1))
        if len(bad):
            shown = rows[bad[0]][outside[bad[0]]][0]
            raise StructureError(f"{path}: {len(bad)} atom(s) have a {name} that PDB columns cannot hold "
                                 f"(e.g. atom {bad[0] + 1}: {shown:g}; PDB holds {holds}); "
                                 "write mmCIF (.cif) instead")


def output_format(path: Path) -> tuple[str, bool]:
    """('pdb' | 'mmcif', gzip?) from the file name."""
    name = path.name.lower()
    compress = name.endswith(".gz")
    stem = name.removesuffix(".gz")
    if stem.endswith(_PDB_SUFFIXES):
        return "pdb", compress
    if stem.endswith(_MMCIF_SUFFIXES):
        return "mmcif", compress
    raise StructureError(f"{path}: unknown extension; use .pdb, .ent, .cif or .mmcif (optionally + .gz)")


def _moved(structure: Structure, coords: np.ndarray) -> gemmi.Structure:
    """A copy of the parsed file with the atoms of the structure's model at ``coords``."""
    st = structure._template.clone()
    model = st[structure.model_number - 1]
    _place(model, coords)
    _set_elements(model, structure)
    return st


def _moved_model(template: gemmi.Model, coords: np.ndarray) -> gemmi.Model:
    """A copy of ``template`` with its atoms at ``coords``."""
    model = template.clone()
    _place(model, coords)
    return model


def _place(model: gemmi.Model, coords: np.ndarray) -> None:
    rows = iter(np.round(coords, 3).tolist())
    for ch in model:
        for res in ch:
            for atom in res:
                atom.pos = gemmi.Position(*next(rows))


def _set_elements(model: gemmi.Model, structure: Structure) -> None:
    """Give ``model`` (the structure's, as parsed) the elements read (gemmi's guesses from
    atom names corrected, see :mod:`core.protein.reading`), for the files gemmi writes."""
    elements = iter(structure.atoms.element.tolist())
    for ch in model:
        for res in ch:
            for atom in res:
                element = next(elements)
                if atom.element.name != element:
                    atom.element = gemmi.Element(element)


def _pdb_text(st: gemmi.Structure, structure: Structure, moved: bool) -> str:
    options = gemmi.PdbWriteOptions()
    options.preserve_serial = True
    options.conect_records = True
    text = st.make_pdb_string(options)
    if structure.source_format == "pdb":
        text = _with_input_header(text, structure._text, _AS_READ + (() if moved else _AS_READ_UNMOVED))
    return text


def _with_input_header(written: str, original: str, as_read: tuple[str, ...] = ()) -> str:
    """Insert into gemmi's PDB output the header records of the input of a type gemmi did
    not write (COMPND, SOURCE, AUTHOR, REVDAT, JRNL, FORMUL, SITE, ...), in standard order;
    the records of the types ``as_read`` are the input's, not gemmi's."""
    rank = {record: _PDB_HEADER_ORDER.index(_SAME_RANK.get(record, record)) for record in _PDB_HEADER_ORDER}
    lines = [line for line in written.splitlines() if _record(line) not in as_read]
    n_header = next(
        (k for k, line in enumerate(lines) if _record(line) in _COORDINATE_RECORDS), len(lines)
    )
    present = {_record(line) for line in lines}
    extra = []
    for line in original.splitlines():
        record = _record(line)
        if record in _COORDINATE_RECORDS:
            break
        if record in rank and (record not in present or record in as_read):
            extra.append(line.rstrip("\r"))
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


_ATOM_RECORDS = ("ATOM  ", "HETATM")
_COLUMNS = (30, 38, 46)
"""Where the x, y and z fields (8 characters each) of a PDB atom record start."""


def _patched_pdb(structure: Structure, coords: np.ndarray) -> str | None:
    """The PDB input with only the coordinates (columns 31-54) of the model's atoms that
    moved rewritten, and the SSBOND, LINK and CISPEP records whose distance or angle gemmi
    finds changed: every other byte stays as read. None when the atom records of the model
    are not the atoms read, in that order (then gemmi writes the file)."""
    text, read = structure._text, structure.coords
    moved = np.flatnonzero(np.any(coords != read, axis=1))
    if not len(moved):
        return text
    lines = text.splitlines(keepends=True)
    model, rows = 0, []
    for k, line in enumerate(lines):
        if _record(line) == "MODEL":
            model += 1
        elif line.startswith(_ATOM_RECORDS) and max(model, 1) == structure.model_number:
            rows.append(k)
    if len(rows) != len(read):
        return None
    try:
        values = np.array([[float(lines[k][c : c + 8]) for c in _COLUMNS] for k in rows]).reshape(-1, 3)
    except ValueError:
        return None
    if not np.allclose(values, read, rtol=0, atol=1e-6):
        return None
    for atom, xyz in zip(moved, np.round(coords[moved], 3) + 0.0):  # + 0.0: no "-0.000"
        lines[rows[atom]] = lines[rows[atom]][:30] + "".join(f"{v:8.3f}" for v in xyz) + lines[rows[atom]][54:]
    before, after = _geometry_records(structure._template), _geometry_records(_moved(structure, coords))
    changed = [k for k, (old, new) in enumerate(zip(before, after)) if old != new]
    at = [k for k, line in enumerate(lines) if _record(line) in _AS_READ_UNMOVED]
    if changed and [_record(lines[k]) for k in at] != [_record(line) for line in after]:
        return None  # the input's records are not gemmi's, one for one
    for k in changed:
        line = lines[at[k]]
        lines[at[k]] = after[k] + line[len(line.rstrip("\r\n")):]
    return "".join(lines)


def _geometry_records(st: gemmi.Structure) -> list[str]:
    """gemmi's SSBOND, LINK and CISPEP lines of ``st``, with distances and angles from its atoms."""
    options = gemmi.PdbWriteOptions()
    options.atom_records = options.seqres_records = options.conect_records = False
    return [line for line in st.make_pdb_string(options).splitlines() if _record(line) in _AS_READ_UNMOVED]


def _mmcif_text(st: gemmi.Structure, structure: Structure) -> str:
    """gemmi's mmCIF of ``st``: for mmCIF input, the input's categories with the atoms
    written anew (when :func:`_patched_atom_site` cannot patch them in place)."""
    if structure.source_format != "mmcif":
        return st.make_mmcif_document().as_string()
    doc = gemmi.cif.read_string(structure._text)
    groups = gemmi.MmcifOutputGroups(False, atoms=True, group_pdb=True, auth_all=True)
    st.update_mmcif_block(doc[0], groups)
    return doc.as_string()


_TOKEN = re.compile(r"""'[^']*'(?=\s|$)|"[^"]*"(?=\s|$)|\S+""")


def _patched_atom_site(structure: Structure, coords: np.ndarray) -> str | None:
    """The mmCIF input with only the coordinates of the model's atoms that moved rewritten,
    each with as many decimals as it had (3 at least): every other byte stays as read. None
    when the ``_atom_site`` loop is not laid out one atom per line in the order read (then
    gemmi writes the atoms)."""
    text, read = structure._text, structure.coords
    lines = text.splitlines(keepends=True)
    start = next((k for k, line in enumerate(lines) if line.startswith("_atom_site.")), None)
    if start is None or start == 0 or lines[start - 1].strip() != "loop_":
        return None
    tags = []
    while start + len(tags) < len(lines) and lines[start + len(tags)].startswith("_atom_site."):
        tags.append(lines[start + len(tags)].split()[0].removeprefix("_atom_site."))
    if not {"Cartn_x", "Cartn_y", "Cartn_z"} <= set(tags):
        return None
    columns = [tags.index(f"Cartn_{axis}") for axis in "xyz"]
    first = start + len(tags)
    stop = next((k for k in range(first, len(lines))
                 if lines[k].startswith(("_", "loop_", "#", "data_", ";")) or not lines[k].strip()), len(lines))
    rows = [_TOKEN.findall(line) for line in lines[first:stop]]
    if any(len(tokens) != len(tags) for tokens in rows):
        return None  # a row over several lines
    if "pdbx_PDB_model_num" in tags:
        column = tags.index("pdbx_PDB_model_num")
        numbers = list(dict.fromkeys(tokens[column] for tokens in rows))  # in file order
        if len(numbers) < structure.model_number:
            return None
        chosen = numbers[structure.model_number - 1]
        kept = [k for k, tokens in enumerate(rows) if tokens[column] == chosen]
    else:
        kept = list(range(len(rows)))
    if len(kept) != len(read):
        return None
    try:
        values = np.array([[rows[k][c] for c in columns] for k in kept], dtype=np.float64).reshape(-1, 3)
    except ValueError:
        return None
    if not np.allclose(values, read, rtol=0, atol=1e-6):
        return None  # not the atoms read, in that order: leave the writing to gemmi
    for atom in np.flatnonzero(np.any(coords != read, axis=1)):
        k = first + kept[atom]
        spans = [m.span() for m in _TOKEN.finditer(lines[k])]
        line = lines[k]
        for c, value in sorted(zip(columns, coords[atom]), reverse=True):
            begin, end = spans[c]
            decimals = len(line[begin:end].partition(".")[2])
            line = line[:begin] + f"{value:.{max(decimals, 3)}f}" + line[end:]
        lines[k] = line
    return "".join(lines)


STAGING = ".staging-"
"""In the name of a file being written (see :func:`staging_file`)."""


def new_file_mode() -> int:
    """The permissions a new file gets under the process's umask (0o644 under the usual 022,
    0o600 under 077): a temporary file renamed into place is made with 0o600 whatever the umask."""
    umask = os.umask(0o077)  # (os.umask can only be read by setting it; set back at once)
    os.umask(umask)
    return 0o666 & ~umask


def staging_file(path: Path, suffix: str = ".tmp") -> tuple[int, str]:
    """A new file beside ``path`` (descriptor and name) for its content until it is renamed onto
    it, named ``.NAME.staging-PID-…``; the staging files in that folder of processes that have
    ended (killed mid-write) are removed first."""
    for stale in path.parent.glob(f".*{STAGING}*"):
        pid = stale.name.partition(STAGING)[2].split("-")[0]
        if pid.isdigit() and not process_alive(int(pid)) and stale.is_file() and not stale.is_symlink():
            with contextlib.suppress(OSError):
                stale.unlink()
    return tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}{STAGING}{os.getpid()}-", suffix=suffix)


def process_alive(pid: int) -> bool:
    """Whether process ``pid`` runs (another user's included)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        pass  # another user's process
    return True


def atomic_write(path: Path, data: bytes) -> None:
    """Write ``data`` to a temporary file next to ``path``, then rename it onto ``path`` (a new
    file gets the permissions the umask allows, a replaced one keeps its own)."""
    mode = path.stat().st_mode & 0o777 if path.exists() else new_file_mode()
    fd, tmp = staging_file(path)
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
