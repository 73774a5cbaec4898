"""The editor's map view: time to contour a map again around a new centre, and to correlate
the edited segment with the map.

Run with ``python benchmarks/bench_map_view.py``. The map is each entry's density (gemmi,
:func:`core.surfaces.volume.model_density`) on grids of 0.5 and 1 Å; the centre moves to
residues spread over the structure. A contour is what the editor does when the centre moves
(:meth:`app.editor.scene.map_mesh.MapMesh.contour` without its render): the block of the
map around the centre, marching cubes at 1 σ, the triangles beyond the radius dropped, the
mesh into the drawn pyvista data. Target: a 30 Å box (radius 15 Å) within 50 ms. The
correlation is the one the Map dock shows during a drag, of the first segment's heavy atoms
(:class:`core.fitting.map_target.MapTarget`). Medians over the centres, in milliseconds.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pyvista as pv

from app.polydata import to_polydata
from core.fitting.map_target import MapTarget
from core.protein.reading import read_structure
from core.protein.structure import ca_rows
from core.surfaces.volume import model_density

DATA = Path(__file__).resolve().parents[1] / "tests" / "data"
ENTRIES = ("4AKE_adk_open.pdb.gz", "4YVS.cif.gz")
SPACINGS = (0.5, 1.0)
RADII = (10.0, 15.0, 20.0)
CENTRES = 20
RESOLUTIONS = (4.0, 8.0)


def median_ms(function: object, arguments: list) -> float:
    times = []
    for argument in arguments:
        start = time.perf_counter()
        function(argument)
        times.append(time.perf_counter() - start)
    return 1e3 * float(np.median(times))


def main() -> None:
    print(f"{'entry':<22}{'atoms':>7}{'grid Å':>8}{'map points':>12}"
          + "".join(f"{f'{2 * r:.0f} Å box ms':>14}" for r in RADII) + f"{'triangles (30 Å)':>18}")
    drawn = pv.PolyData()
    for name in ENTRIES:
        structure = read_structure(DATA / name)
        ca = structure.coords[ca_rows(structure)]
        centres = ca[np.linspace(0, len(ca) - 1, CENTRES).astype(int)]
        for spacing in SPACINGS:
            density = model_density(structure.atoms, spacing=spacing, resolution=2 * spacing)
            value = density.sigma_level(1.0)
            cells = {}

            def contour(centre: np.ndarray, radius: float) -> None:
                drawn.shallow_copy(to_polydata(density.contour_around(value, centre, radius)))
                cells[radius] = cells.get(radius, []) + [drawn.n_cells]

            times = [median_ms(lambda c, r=r: contour(c, r), list(centres)) for r in RADII]
            print(f"{name:<22}{structure.n_atoms:>7}{spacing:>8.1f}{density.values.size:>12,}"
                  + "".join(f"{t:>14.1f}" for t in times) + f"{int(np.median(cells[15.0])):>18,}")
    print()
    print(f"{'entry':<22}{'segment atoms':>14}{'resolution Å':>14}{'correlation ms':>16}")
    for name in ENTRIES:
        structure = read_structure(DATA / name)
        density = model_density(structure.atoms, spacing=1.0, resolution=4.0)
        segment = structure.segments[0]
        rows = np.concatenate([np.arange(a, b) for a, b in zip(segment.atom_start, segment.atom_stop)])
        rows = rows[structure.atoms.element[rows] != "H"]
        for resolution in RESOLUTIONS:
            target = MapTarget(density, resolution, structure.coords[rows])
            moved = [structure.coords[rows] + shift for shift in np.linspace(0.0, 1.0, 10)]
            print(f"{name:<22}{len(rows):>14}{resolution:>14.1f}{median_ms(target.correlation, moved):>16.1f}")


if __name__ == "__main__":
    main()
