"""The level-by-level entry point: every kind names its stages as it builds, and a built surface
pickles (the editor builds it in another process) into one that gives the same views."""

from __future__ import annotations

import pickle
from pathlib import Path

import numpy as np
import pytest

from core.protein.reading import read_atoms
from core.surfaces.dna import ideal_bdna
from core.surfaces.levelled import build_surface

DATA = Path(__file__).resolve().parents[2] / "data"
SES_STAGES = [f"molecular surface ({stage})" for stage in
              ("distances to the atoms", "the solvent", "distance transform", "refinement")]


@pytest.mark.parametrize(("kind", "stages"), [
    ("ses", [*SES_STAGES, "triangles"]),
    ("globe", [*SES_STAGES, "fitting the globe", "levels"]),
    ("dna", [*SES_STAGES, "fitting the cylinder", "levels"]),
    ("remesh", [*SES_STAGES, "remeshing"]),
    ("map", ["density map", "wavelet levels"]),
])
def test_stages_are_named_and_the_surface_pickles(kind: str, stages: list[str]) -> None:
    atoms = ideal_bdna("CGCGAATTCGCG") if kind == "dna" else read_atoms(DATA / "1UBQ.pdb.gz")
    told: list[str] = []
    surface = build_surface(kind, atoms, progress=told.append)
    assert told == stages
    copy = pickle.loads(pickle.dumps(surface))
    assert (copy.kind, copy.max_level, copy.errors, copy.fractional) == \
        (surface.kind, surface.max_level, surface.errors, surface.fractional)
    colourings = ("potential", "bfactor") if kind == "map" else ("potential", "curvature", "bfactor")
    for level in sorted({0, surface.max_level}):
        for colouring in (None, *colourings):
            (mesh, values), (copied, copied_values) = surface.view(level, colouring), copy.view(level, colouring)
            np.testing.assert_allclose(copied.vertices, mesh.vertices, rtol=0, atol=1e-9)  # Å (another memory layout)
            np.testing.assert_array_equal(copied.faces, mesh.faces)
            if colouring is not None:
                np.testing.assert_allclose(copied_values, values, rtol=1e-9, atol=1e-12)


def test_the_dna_cylinder_of_a_protein_dna_complex_is_its_duplex_alone() -> None:
    atoms = read_atoms(DATA / "1LCD.cif.gz")  # the lac repressor headpiece on an 11-base-pair operator
    mesh, _ = build_surface("dna", atoms).view()  # (about the whole complex, rays missed it between the two)
    dna = atoms.coords[atoms.category == "nucleic"]
    near_dna = np.linalg.norm(mesh.vertices[:, None] - dna[None], axis=2).min(axis=1)
    assert np.percentile(near_dna, 99) < 4.0  # on the duplex, not on the protein
    axis = np.linalg.svd(dna - dna.mean(axis=0))[2][0]
    assert np.ptp(mesh.vertices @ axis) < np.ptp(dna @ axis)  # along the duplex, within its length
