"""Time to build each kind of surface for 1UBQ, 1TIM and 4YVS, and an ideal 32-bp B-DNA.

Prints a table; run with ``python benchmarks/bench_surfaces.py``. Target: the molecular
surface of about 5,000 atoms in seconds. The globe, cylinder and remeshing times exclude
the molecular surface they are cast onto; the map column is the model density plus all
its wavelet levels. Best of ``REPEATS`` runs.
"""

from __future__ import annotations

from pathlib import Path

from timing import best_ms

from core.protein.reading import read_atoms
from core.surfaces.dna import ideal_bdna
from core.surfaces.globe import cylinder, globe
from core.surfaces.molecular import molecular_surface
from core.surfaces.remesh import remesh
from core.surfaces.volume import model_density

DATA = Path(__file__).resolve().parents[1] / "tests" / "data"
ENTRIES = ("1UBQ.pdb.gz", "1TIM.pdb.gz", "4YVS.cif.gz")
REPEATS = 2


def main() -> None:
    print(f"{'entry':<22}{'atoms':>7}{'grid Å':>8}{'triangles':>11}{'SES s':>8}{'globe s':>9}"
          f"{'dna s':>7}{'remesh5 s':>11}{'map s':>7}")
    inputs = [(name, read_atoms(DATA / name)) for name in ENTRIES]
    inputs.append(("ideal B-DNA 32 bp", ideal_bdna(("CGCGAATTCGCG" * 3)[:32])))
    for name, atoms in inputs:
        ses = best_ms(lambda: molecular_surface(atoms).mesh, REPEATS) / 1e3  # noqa: B023
        surface = molecular_surface(atoms)
        mesh = surface.mesh
        shape = cylinder if name.startswith("ideal") else globe
        shaped = best_ms(lambda: shape(surface), REPEATS) / 1e3  # noqa: B023
        remeshed = best_ms(lambda: remesh(surface, 5), REPEATS) / 1e3  # noqa: B023

        def density_levels() -> None:
            density = model_density(atoms)  # noqa: B023
            for level in range(density.max_level + 1):
                density.at_level(level)

        levels = best_ms(density_levels, REPEATS) / 1e3
        globe_s, dna_s = (f"{shaped:9.2f}", f"{'-':>7}") if shape is globe else (f"{'-':>9}", f"{shaped:7.2f}")
        print(f"{name:<22}{int(surface.mask.sum()):>7}{surface.field.spacing:>8.2f}{mesh.n_faces:>11}"
              f"{ses:>8.2f}{globe_s}{dna_s}{remeshed:>11.2f}{levels:>7.2f}")


if __name__ == "__main__":
    main()
