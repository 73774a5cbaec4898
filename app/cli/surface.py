"""``ribbonwave surface``: a molecular surface, globe, DNA cylinder, remeshed surface or
density-map contour at a level, written as a VTK PolyData (.vtp), PLY (.ply) or an
off-screen rendered PNG image (.png). The surfaces come from :mod:`core.surfaces.levelled`; this
module only turns them into pyvista meshes and files.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import time
from pathlib import Path

import numpy as np

from app.arguments import bounded, writable_output
from app.cli.structure import model_argument
from app.errors import InputError
from app.polydata import scalar_style, to_polydata
from core.protein.input_files import StructureError
from core.protein.reading import read_atoms
from core.protein.structure import AtomTable
from core.protein.writing import new_file_mode, staging_file
from core.surfaces.dna import ideal_bdna
from core.surfaces.levelled import KINDS, UNITS, LevelledSurface, build_surface
from core.surfaces.map_file import MAP_SUFFIXES, read_map
from core.surfaces.mesh import TriangleMesh
from core.surfaces.molecular import COLOURINGS
from core.surfaces.volume import MapError

OUTPUTS = (".vtp", ".ply", ".png")
IDEAL_DNA_REPEAT = "CGCGAATTCGCG"
"""Sequence of the ideal B-DNA model, repeated (the Dickerson dodecamer of 1BNA)."""


def surface_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", type=Path, nargs="?", metavar="FILE",
                        help="structure (PDB or mmCIF, optionally gzipped), or a CCP4/MRC map or MTZ file for --kind map")
    model_argument(parser)
    parser.add_argument("--kind", choices=KINDS, default="ses",
                        help="ses: molecular surface (default); globe: sphere-topology spline surface; "
                        "dna: cylinder about the helix axis; remesh: 6·4^L triangles; map: density contour")
    parser.add_argument("--level", type=bounded(float, 0, 10), metavar="L",
                        help="level (default the finest: 5 for globe/dna/remesh, the map's wavelet levels)")
    parser.add_argument("--color", choices=COLOURINGS, help="colour by electrostatic potential, curvature or B-factor")
    parser.add_argument("--site", metavar="LIGAND",
                        help="remesh only the patch within 10 Å of this ligand (residue name, or CHAIN:NUMBER)")
    parser.add_argument("--ideal-dna", type=int, metavar="N",
                        help=f"instead of FILE, an ideal B-DNA of N base pairs ({IDEAL_DNA_REPEAT} repeated)")
    parser.add_argument("--contour", type=bounded(float, -50, 50), default=1.0, metavar="SIGMA",
                        help="map contour in rms deviations above the mean (default 1)")
    parser.add_argument("--probe", type=bounded(float, 0, 5), default=1.4, metavar="Å",
                        help="probe radius (default 1.4 Å, at most 5)")
    parser.add_argument("--spacing", type=bounded(float, 0.2, 5), metavar="Å",
                        help="grid step of the molecular surface, 0.2 to 5 Å (default 0.5 Å, coarser for large entries)")
    parser.add_argument("-o", "--output", required=True, type=Path, metavar="OUT",
                        help="output file: .vtp, .ply or .png")
    parser.add_argument("--overwrite", action="store_true", help="replace OUT if it exists")


def run_surface(args: argparse.Namespace) -> int:
    suffix = args.output.suffix.lower()
    if suffix not in OUTPUTS:
        raise InputError(f"{args.output}: unknown output type; use {', '.join(OUTPUTS)}")
    writable_output(args.output, args.overwrite)
    if (args.file is None) == (args.ideal_dna is None):
        raise InputError("give either FILE or --ideal-dna N")
    if args.site is not None and args.kind != "remesh":
        raise InputError("--site only applies to --kind remesh")
    start = time.perf_counter()
    atoms, density = _inputs(args)
    site = None if args.site is None else _site(atoms, args.site)
    try:
        surface = build_surface(args.kind, atoms, density=density, site=site, contour=args.contour,
                                probe=args.probe, spacing=args.spacing)
        mesh, scalars = surface.view(args.level, args.color)
    except ValueError as error:
        raise InputError(str(error)) from None
    built = time.perf_counter() - start
    _write(mesh, scalars, args.color, args.output)
    _report(surface, mesh, args, built)
    return 0


def _inputs(args: argparse.Namespace) -> tuple[AtomTable | None, object]:
    """The model and, for a map file, the map."""
    if args.ideal_dna is not None:
        if not 4 <= args.ideal_dna <= 1000:
            raise InputError(f"--ideal-dna must lie in [4, 1000] base pairs; got {args.ideal_dna}")
        repeats = -(-args.ideal_dna // len(IDEAL_DNA_REPEAT))
        return ideal_bdna((IDEAL_DNA_REPEAT * repeats)[: args.ideal_dna]), None
    name = args.file.name.lower().removesuffix(".gz")
    try:
        if name.endswith(MAP_SUFFIXES):
            if args.kind != "map":
                raise InputError(f"{args.file}: a density map can only be shown with --kind map")
            return None, read_map(args.file)
        return read_atoms(args.file, args.model), None
    except (StructureError, MapError) as error:
        raise InputError(str(error)) from None


def _site(atoms: AtomTable | None, spec: str) -> np.ndarray:
    """Atoms of the ligand ``spec`` ('BEN' or 'A:1')."""
    if atoms is None:
        raise InputError("--site needs a structure")
    ligand = atoms.category == "ligand"
    chain, _, number = spec.rpartition(":")
    if chain and number.lstrip("-").isdigit():
        mask = ligand & (atoms.chain == chain) & (atoms.resseq == int(number))
    else:
        mask = ligand & (atoms.resname == spec.upper())
    if not mask.any():
        names = ", ".join(sorted(set(atoms.resname[ligand].tolist()))) or "none"
        raise InputError(f"no ligand {spec!r} in {atoms.entry_id} (ligands: {names})")
    return mask


def _write(mesh: TriangleMesh, scalars: np.ndarray | None, colouring: str | None, path: Path) -> None:
    """Write atomically: to a temporary file beside ``path``, then rename."""
    polydata = to_polydata(mesh, scalars, colouring or "values")
    fd, tmp = staging_file(path, path.suffix)
    os.close(fd)
    try:
        if path.suffix.lower() == ".png":
            _render(polydata, scalars, colouring, tmp)
        else:
            polydata.save(tmp)
        os.chmod(tmp, new_file_mode())
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def _render(polydata, scalars: np.ndarray | None, colouring: str | None, path: str) -> None:
    import pyvista as pv

    plotter = pv.Plotter(off_screen=True, window_size=(900, 900))
    try:
        if scalars is None:
            plotter.add_mesh(polydata, color="lightsteelblue", smooth_shading=True)
        else:
            cmap, clim = scalar_style(colouring, scalars)
            plotter.add_mesh(polydata, scalars=colouring, cmap=cmap, clim=clim, smooth_shading=True,
                             scalar_bar_args={"title": f"{colouring} ({UNITS[colouring]})"})
        plotter.set_background("white")
        plotter.view_isometric()
        normal = np.asarray(polydata.compute_normals(cell_normals=True, point_normals=False).cell_data["Normals"]).mean(axis=0)
        if np.linalg.norm(normal) > 0.5:  # a patch: look at it from outside
            centre, size = np.asarray(polydata.center), polydata.length
            up = np.cross(normal, [1.0, 0, 0] if abs(normal[0]) < 0.9 else [0, 1.0, 0])
            plotter.camera_position = [tuple(centre + 2 * size * normal), tuple(centre), tuple(up)]
        plotter.screenshot(path)
    finally:
        plotter.close()


def _report(surface: LevelledSurface, mesh: TriangleMesh, args: argparse.Namespace, seconds: float) -> None:
    level = surface.max_level if args.level is None else args.level
    print(f"{args.kind} surface at level {level:g} of {surface.max_level}: {len(mesh.vertices)} vertices, "
          f"{mesh.n_faces} triangles, {'closed' if mesh.is_closed() else 'open'}; built in {seconds:.2f} s")
    if surface.errors:
        what = "rms difference of map values" if args.kind == "map" else "rms error (Å)"
        print(f"  level  {what}")
        for lv, error in surface.errors:
            print(f"  {lv:>5}  {error:.3f}")
    print(f"wrote {args.output}")
