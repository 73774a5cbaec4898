"""Before the levels of a map fit: the chain's smaller dynamic domain moved as a rigid body.

A domain that must turn 30–60° to reach its density is beyond the levels: at level 0 the
whole chain is four control points, and from level 1 on, a domain's few control points
bend it rather than turn it, into the nearest local optimum. iMODFIT and Flex-EM reach
such motions by moving rigid parts first; so does this stage.

The domains are those of the Gaussian network model (GNM) of the chain's Cα (Bahar et al.
1997): the sign of the slowest mode splits the chain in two, smoothed along the sequence so
that it crosses between them only at hinges (:func:`dynamic_domains`). The smaller one is
fitted as a rigid body (rotation about its centroid and translation) into the map blurred
to :data:`RESOLUTION`, by L-BFGS on the correlation from :data:`TURNS` starts, the chain
held together where it crosses between the domains (:data:`HINGE_WEIGHT`), and kept where it
gains :data:`GAIN` of correlation. In the wavelet framework the motion is an edit
at the finest level: each finest control point whose nearest residue lies in the domain
moves with it, and the residues follow the curve (those inside the domain
rigidly, exactly, those at its hinges bent), as when a control point is dragged.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import numpy as np
from scipy import linalg, ndimage
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

from core.fitting.coarse_to_fine import LevelFit
from core.fitting.stoppable import minimize_until_cancelled
from core.protein.model import Edit, EditableModel
from core.protein.ribbon import Ribbon
from core.protein.structure import ca_rows

if TYPE_CHECKING:
    from core.fitting.map_target import MapTarget

DOMAINS = -1
"""The "level" of this stage in a fit's levels: before level 0."""
GNM_CUTOFF = 7.3
"""Å: Cα closer than this are joined in the Gaussian network model (Bahar et al.)."""
SMOOTHING = 15
"""Residues: the window of the median filter that keeps a domain from stray pieces."""
SMALLEST = 20
"""Fewest residues a domain (and what is left of the chain) must have to be moved."""
RESOLUTION = 20.0
"""Å: the map as the domain sees it (its helices and loops blurred away, its basin wide)."""
GAIN = 0.02
"""Correlation (at :data:`RESOLUTION`) a domain's motion must gain to be kept."""
TURNS = (30.0, 60.0)
"""Degrees: each start turns the domain by one of these about the x, y or z axis, either
way, or not at all (13 starts)."""
ITERATIONS = 60
"""Most L-BFGS iterations from each start."""
HINGE_WEIGHT = 0.01
"""Correlation per Å² that a Cα pair where the chain crosses between the domains is pulled
apart beyond :data:`HINGE_SLACK` (:func:`_rigid_fit`)."""
HINGE_SLACK = 1.0
"""Å a hinge's Cα pair may part freely (its loop takes that up)."""


def dynamic_domains(ca: np.ndarray) -> np.ndarray:
    """(n,) bool: the smaller of the two dynamic domains of a chain with Cα ``ca`` (n, 3)
    in sequence order: the sign of the slowest nonzero mode of its Gaussian network
    (:data:`GNM_CUTOFF`), median-filtered along the chain (:data:`SMOOTHING`). All False
    where either part is smaller than :data:`SMALLEST` or the network falls apart."""
    n = len(ca)
    none = np.zeros(n, dtype=bool)
    if n < 2 * SMALLEST:
        return none
    pairs = cKDTree(ca).query_pairs(GNM_CUTOFF, output_type="ndarray")
    kirchhoff = np.zeros((n, n))
    kirchhoff[pairs[:, 0], pairs[:, 1]] = kirchhoff[pairs[:, 1], pairs[:, 0]] = -1.0
    kirchhoff[np.diag_indices(n)] = -kirchhoff.sum(axis=1)
    values, vectors = linalg.eigh(kirchhoff, subset_by_index=[0, 1])
    if values[1] < 1e-6:  # more than one connected piece
        return none
    positive = vectors[:, 1] > 0
    smaller = positive if positive.sum() < n - positive.sum() else ~positive
    smaller = ndimage.median_filter(smaller, size=SMOOTHING, mode="nearest")
    return smaller if SMALLEST <= smaller.sum() <= n - SMALLEST else none


def fit_domain(model: EditableModel, segments: Sequence[int], target: MapTarget, heavy: np.ndarray,
               occupancy: np.ndarray, *, cancelled: Callable[[], bool] = lambda: False) -> LevelFit:
    """Move the smaller dynamic domain of ``segments`` (one chain, in order) as a rigid body
    into ``target`` (a :class:`~core.fitting.map_target.MapTarget`) seen at :data:`RESOLUTION`,
    where that gains :data:`GAIN` of correlation; ``heavy`` are the rows of the model's atoms
    the map shows, ``occupancy`` how much of each (:func:`core.fitting.map_target.occupancies`).
    The edits (one per segment moved, none where nothing moved) are applied
    to ``model``; the score is the correlation at :data:`RESOLUTION` after the stage."""
    began = time.perf_counter()
    at = target.blurred(RESOLUTION)
    residues = np.concatenate([model.segments[s].residue_index for s in segments])
    domain = dynamic_domains(model.coords[ca_rows(model.structure)[residues]])
    coords = model.coords[heavy]
    before = at.correlation(coords, occupancy)
    if not domain.any() or cancelled():
        return LevelFit(DOMAINS, 0, before, time.perf_counter() - began, (), at.resolution)
    moving = np.isin(model.structure.atom_residue[heavy], residues[domain])
    crossing = np.flatnonzero(domain[1:] != domain[:-1])
    inside = np.where(domain[crossing], crossing, crossing + 1)
    outside = np.where(domain[crossing], crossing + 1, crossing)
    position = np.searchsorted(heavy, ca_rows(model.structure)[residues])  # each Cα among the heavy atoms
    turn, shift, cc = _rigid_fit(at, coords, occupancy, moving, (position[inside], position[outside]), cancelled)
    if cc - before < GAIN or cancelled():
        return LevelFit(DOMAINS, 0, before, time.perf_counter() - began, (), at.resolution)
    pivot = coords[moving].mean(axis=0)

    def moved(points: np.ndarray) -> np.ndarray:
        return turn.apply(points - pivot) + pivot + shift

    edits, n_points, offset = [], 0, 0
    for s in segments:
        ribbon, count = model.ribbons[s], len(model.segments[s])
        inside = np.flatnonzero(domain[offset:offset + count])
        owned = _owned_points(ribbon, domain[offset:offset + count])
        offset += count
        if len(inside):
            points = ribbon.points.copy()
            points[owned] = moved(points[owned])
            rows = np.concatenate([np.arange(a, b) for a, b in zip(model.segments[s].atom_start[inside],
                                                                  model.segments[s].atom_stop[inside])])
            edit = Edit(s, ribbon.points, points, inside, rows, model.coords[rows], moved(model.coords[rows]))
            model.apply(edit)
            edits.append(edit)
            n_points += int(owned.sum())
    score = at.correlation(model.coords[heavy], occupancy)
    return LevelFit(DOMAINS, n_points, score, time.perf_counter() - began, tuple(edits), at.resolution,
                    motion=f"the smaller dynamic domain, {int(domain.sum())} residues, turned "
                           f"{np.degrees(turn.magnitude()):.0f}° and moved {np.linalg.norm(shift):.1f} Å")


def _owned_points(ribbon: Ribbon, domain: np.ndarray) -> np.ndarray:
    """(n_points,) bool: the finest control points whose nearest residue (by the point's
    Greville abscissa) lies in ``domain`` (n_residues,)."""
    knots = ribbon.space.knots
    greville = (knots[1:-3] + knots[2:-2] + knots[3:-1]) / 3.0
    nearest = np.abs(greville[:, None] - ribbon.residue_u[None, :]).argmin(axis=1)
    return domain[nearest]


def _rigid_fit(at: MapTarget, coords: np.ndarray, occupancy: np.ndarray, moving: np.ndarray,
               hinges: tuple[np.ndarray, np.ndarray], cancelled: Callable[[], bool]
               ) -> tuple[Rotation, np.ndarray, float]:
    """The rotation (about the moving atoms' centroid), translation and correlation of the
    best rigid placement of ``coords[moving]`` in ``at`` from the :data:`TURNS` starts, the
    correlation less :data:`HINGE_WEIGHT` times the squared parting, beyond :data:`HINGE_SLACK`,
    of the hinges' Cα pairs ``hinges`` (moving, fixed; rows of ``coords``). A domain turned
    about its centroid for the map alone left adenylate kinase's chain 11–12 Å apart at a
    hinge, which the regularization then closed by moving the loops near it up to 7 Å, one
    of two ways, as the last bits of the start fell."""
    pivot = coords[moving].mean(axis=0)
    arm = coords[moving] - pivot
    inside, outside = hinges
    rest = np.linalg.norm(coords[inside] - coords[outside], axis=1) + HINGE_SLACK
    best = {"value": -np.inf, "cc": -np.inf, "x": np.zeros(6)}

    def negative(x: np.ndarray) -> tuple[float, np.ndarray]:
        rotation = Rotation.from_rotvec(x[:3])
        placed = coords.copy()
        turned = rotation.apply(arm)
        placed[moving] = turned + pivot + x[3:]
        cc, gradient = at.gradient(placed, occupancy)
        apart = placed[inside] - placed[outside]
        length = np.linalg.norm(apart, axis=1)
        excess = np.maximum(length - rest, 0.0)
        value = cc - HINGE_WEIGHT * float(np.sum(excess**2))
        gradient[inside] -= (2.0 * HINGE_WEIGHT * excess / np.maximum(length, 1e-9))[:, None] * apart
        if value > best["value"]:
            best.update(value=value, cc=cc, x=x.copy())
        pull = gradient[moving]
        torque = np.cross(turned, pull).sum(axis=0)
        return -value, -np.concatenate([_left_jacobian(x[:3]).T @ torque, pull.sum(axis=0)])

    for start in _starts():
        if cancelled():
            break
        minimize_until_cancelled(negative, np.concatenate([start, np.zeros(3)]), cancelled,
                                 maxiter=ITERATIONS, gtol=1e-9, ftol=1e-10)
    return Rotation.from_rotvec(best["x"][:3]), best["x"][3:], float(best["cc"])


def _starts() -> list[np.ndarray]:
    """Rotation vectors of the starts: none, then each of :data:`TURNS` about each axis, both ways."""
    turns = [sign * np.radians(angle) * axis for angle in TURNS for axis in np.eye(3) for sign in (1.0, -1.0)]
    return [np.zeros(3), *turns]


def _left_jacobian(rotvec: np.ndarray) -> np.ndarray:
    """(3, 3) the left Jacobian of SO(3) at ``rotvec``: a change ``d`` of the rotation vector
    turns the rotated points by the small rotation ``J d``."""
    theta = float(np.linalg.norm(rotvec))
    cross = np.array([[0.0, -rotvec[2], rotvec[1]], [rotvec[2], 0.0, -rotvec[0]], [-rotvec[1], rotvec[0], 0.0]])
    if theta < 1e-8:
        return np.eye(3) + 0.5 * cross
    return (np.eye(3) + (1.0 - np.cos(theta)) / theta**2 * cross
            + (theta - np.sin(theta)) / theta**3 * cross @ cross)
