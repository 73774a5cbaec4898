"""Carson's spline surfaces on real structures: globes of ubiquitin and TIM, the DNA
cylinder of 1BNA and of an ideal 32-bp B-DNA; progressive remeshing."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from core.protein.reading import read_atoms
from core.surfaces.dna import RISE, ideal_bdna
from core.surfaces.globe import cylinder, globe
from core.surfaces.molecular import molecular_surface
from core.surfaces.remesh import remesh

DATA = Path(__file__).resolve().parents[2] / "data"


@pytest.fixture(scope="module", params=["1UBQ.pdb.gz", "1TIM.pdb.gz"])
def protein(request):
    surface = molecular_surface(read_atoms(DATA / request.param))
    return surface, globe(surface)


@pytest.fixture(scope="module")
def ideal_dna():
    surface = molecular_surface(ideal_bdna(("CGCGAATTCGCG" * 3)[:32]))
    return surface, cylinder(surface)


def test_globe_samples_lie_on_the_surface_at_positive_finite_radii(protein) -> None:
    surface, shape = protein
    samples = shape.surface.samples
    assert samples.shape == (64, 64, 3) and shape.surface.net.shape == (35, 32, 3)
    radii = np.linalg.norm(samples - shape.centre, axis=-1)
    assert np.isfinite(radii).all() and radii.min() > 0.5  # the centre lies >= 1 Å inside
    assert np.abs(surface.field.sample(samples)).max() < 0.05  # on the SES
    assert surface.field.sample(shape.centre) > 0  # the centre is inside the molecule


def test_globe_poles_stay_collapsed_at_every_level(protein) -> None:
    _, shape = protein
    for level in (5, 4, 3, 2.5, 1, 0):
        net = shape.surface.net_at(level)
        assert np.ptp(net[0], axis=0).max() < 1e-9 and np.ptp(net[-1], axis=0).max() < 1e-9
        points = shape.surface.points(level)
        assert np.ptp(points[0], axis=0).max() < 1e-9 and np.ptp(points[-1], axis=0).max() < 1e-9


def test_globe_error_decreases_with_level_and_meshes_are_closed(protein) -> None:
    _, shape = protein
    errors = [shape.surface.rms_error(level) for level in range(6)]
    assert all(a > b for a, b in zip(errors, errors[1:])), errors
    for level in (5, 4, 3):
        mesh = shape.surface.mesh(level)
        assert mesh.is_closed() and mesh.volume() > 0
        assert len(mesh.vertices) == 62 * 64 + 2


def test_globe_longitude_is_closed_without_seam(protein) -> None:
    _, shape = protein
    net = shape.surface.net_at(4)
    from core.surfaces.tensor_spline import evaluate_grid

    u = np.linspace(0.05, 0.95, 19)
    ends = evaluate_grid(net, u, [1 - 1e-7, 0.0], (False, True))
    assert np.abs(ends[:, 0] - ends[:, 1]).max() < 1e-4


def test_ideal_bdna_geometry() -> None:
    atoms = ideal_bdna("CGCGAATTCGCG")
    assert len(atoms) == 24 * 11 + 12 * 19  # backbone of 24 nucleotides, 19 base atoms per pair (1BNA: 486, no 5' phosphates)
    phosphorus = atoms.coords[(atoms.name == "P") & (atoms.chain == "A")]
    assert np.allclose(np.diff(phosphorus[:, 2]), RISE)
    assert np.allclose(np.linalg.norm(phosphorus[:, :2], axis=1), 8.91)
    c1 = atoms.coords[atoms.name == "C1'"]
    pair = np.linalg.norm(c1[atoms.chain[atoms.name == "C1'"] == "A"] - c1[atoms.chain[atoms.name == "C1'"] == "B"][::-1], axis=1)
    assert np.allclose(pair, pair[0]) and 10.0 < pair[0] < 11.0  # C1'–C1' across a Watson–Crick pair
    assert set(atoms.resname[atoms.chain == "B"].tolist()) == {"DC", "DG", "DA", "DT"}
    with pytest.raises(ValueError, match="A, C, G, T"):
        ideal_bdna("ACGU")


def test_dna_grooves_fade_by_level_3_while_the_texture_keeps_them(ideal_dna) -> None:
    surface, shape = ideal_dna
    depth = {level: shape.groove_depth(level) for level in (5, 4, 3, 2)}
    assert depth[5] > 6.0  # major and minor grooves, Å
    assert depth[4] > 0.8 * depth[5]
    assert depth[3] < 0.6 * depth[5]
    assert depth[2] < 0.2 * depth[5]
    # the 64 × 64 curvature texture, sampled on the molecular surface, still follows the
    # grooves: concave where the surface is near the axis
    texture = surface.colour("curvature", shape.surface.samples)
    radial = np.linalg.norm(shape.surface.samples - shape.centre - np.outer(
        (shape.surface.samples - shape.centre).reshape(-1, 3) @ shape.axes[2], shape.axes[2]).reshape(64, 64, 3), axis=-1)
    deviation = radial - radial.mean(axis=1, keepdims=True)
    assert np.corrcoef(texture[8:-8].ravel(), deviation[8:-8].ravel())[0, 1] > 0.3
    assert shape.surface.mesh(3).boundary_edges().shape == (2 * 64, 2)  # open only at the two ends


def test_dna_cylinder_of_1bna() -> None:
    surface = molecular_surface(read_atoms(DATA / "1BNA.pdb.gz"))
    shape = cylinder(surface)
    errors = [shape.surface.rms_error(level) for level in range(6)]
    assert all(a > b for a, b in zip(errors, errors[1:]))
    assert np.isfinite(shape.surface.samples).all()
    assert shape.groove_depth(5) > 6.0


def test_cylinder_of_a_globular_protein_is_refused() -> None:
    with pytest.raises(ValueError, match="rays towards the axis miss"):
        cylinder(molecular_surface(read_atoms(DATA / "1UBQ.pdb.gz")))


def test_remeshing_the_whole_surface(protein) -> None:
    surface, _ = protein
    result = remesh(surface, 4)
    assert [m.n_faces for m in result.meshes] == [6, 24, 96, 384, 1536]
    assert all(m.is_closed() and m.volume() > 0 for m in result.meshes)
    assert all(a > b for a, b in zip(result.rms_error, result.rms_error[1:])), result.rms_error
    assert np.abs(surface.field.sample(result.meshes[-1].vertices)).max() < 0.05  # vertices on the SES
    # each level keeps the vertices of the coarser ones
    assert np.array_equal(result.meshes[2].vertices[: len(result.meshes[1].vertices)], result.meshes[1].vertices)


def test_remeshing_the_patch_around_an_active_site() -> None:
    atoms = read_atoms(DATA / "3PTB.pdb.gz")
    benzamidine = atoms.resname == "BEN"
    surface = molecular_surface(atoms, exclude=benzamidine)
    result = remesh(surface, 4, site=atoms.coords[benzamidine])
    assert [m.n_faces for m in result.meshes] == [6, 24, 96, 384, 1536]
    assert [len(m.boundary_edges()) for m in result.meshes] == [6, 12, 24, 48, 96]
    assert all(a > b for a, b in zip(result.rms_error, result.rms_error[1:])), result.rms_error
    # the patch covers the specificity pocket: Asp189 at its bottom is within reach
    asp189 = atoms.coords[(atoms.resname == "ASP") & (atoms.resseq == 189)]
    closest = np.linalg.norm(result.meshes[-1].vertices[:, None] - asp189[None], axis=2).min()
    assert closest < 6.0
    with pytest.raises(ValueError, match="levels"):
        remesh(surface, 9)
