"""Core meshes as pyvista PolyData, and how their per-vertex values are coloured: shared
by the ``surface`` command and the editor's surface panel. pyvista loads on first use, so
commands that draw nothing never import it."""

from __future__ import annotations

import numpy as np

from core.surfaces.mesh import TriangleMesh


def to_polydata(mesh: TriangleMesh, scalars: np.ndarray | None = None, name: str = "values"):  # noqa: ANN201
    """A pyvista.PolyData of a core mesh, with per-vertex ``scalars`` under ``name``."""
    import pyvista as pv

    faces = np.hstack([np.full((mesh.n_faces, 1), 3), mesh.faces]).ravel()
    polydata = pv.PolyData(mesh.vertices, faces)
    if scalars is not None:
        polydata.point_data[name] = scalars
    return polydata


def scalar_style(colouring: str, scalars: np.ndarray) -> tuple[str, tuple[float, float]]:
    """Colour map and range for per-vertex ``scalars`` of ``colouring``: the potential
    symmetric about 0 (95th percentile of |value|), curvature ±0.5 1/Å, B-factors 2–98%."""
    limit = float(np.percentile(np.abs(scalars), 95)) or 1.0
    low, high = np.percentile(scalars, [2, 98])
    clim = {"potential": (-limit, limit), "curvature": (-0.5, 0.5)}.get(colouring, (float(low), float(high)))
    return {"potential": "bwr_r", "curvature": "PiYG"}.get(colouring, "viridis"), clim
