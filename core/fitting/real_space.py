"""Real-space refinement into a map: every residue a rigid body with turning side chains.

The levels move the residues with their curve; at the finest level a control
point still carries about three residues, and each residue keeps its place on the curve
and its rotamer. Here, as the last step of a fit into a map, every residue of the fitted
segments moves on its own: a shift and a rotation about its start Cα, and its side-chain
torsions χ1 … χ4 (:class:`core.fitting.side_chains.Rotors`) turn, all at once, to raise
the map correlation less two penalties:

- **junctions**: the next residue's N and Cα sit on the ideal peptide built on this
  residue's Cα, C and O (as the regularization asks, :mod:`core.geometry.restraints`);
- **overlaps**: pairs may not overlap more than they did at the start (or than
  :data:`~core.geometry.clash_list.CLASH_TARGET`), as the side-chain fit asks.

Inside a residue nothing changes shape: bond lengths, angles, chirality and rings stay as
read, as with every other edit. The gradient is analytic (the correlation's per atom,
carried to each body's shift, rotation and torsions; a rotation vector's through the right
Jacobian of SO(3)), and L-BFGS climbs it, the rotations and torsions in units of
:data:`RADIUS` Å of arc so that each unknown moves atoms about as far. The junctions are
held softly so the climb stays fast; the regularization that follows closes them.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from scipy.spatial.transform import Rotation

from core.fitting.side_chains import CLASH_WEIGHT, Clashes, side_chain_rotors
from core.fitting.stoppable import minimize_until_cancelled
from core.geometry.restraints import ideal_next
from core.geometry.topology import topology
from core.geometry.vectors import cross, summed_rows
from core.protein.model import Edit, EditableModel

JUNCTION_WEIGHT = 0.01
"""CC per Å² of a junction point off the ideal peptide."""
RADIUS = 3.0
"""Å: the arc per radian that a rotation or torsion unknown is measured in."""
ITERATIONS = 600


class ResidueBodies:
    """The residues of ``segments`` as rigid bodies with side-chain rotors, and the ideal
    peptide points (N and Cα) that each carries for the junction after it.

    The unknowns (:attr:`size`) are a shift (Å) per body, then a rotation vector about its
    start Cα per body, then a turn per rotor (both in Å of arc at :data:`RADIUS`)."""

    def __init__(self, model: EditableModel, segments: Sequence[int]) -> None:
        self.start = model.coords.copy()
        starts = np.concatenate([model.segments[s].atom_start for s in segments])
        stops = np.concatenate([model.segments[s].atom_stop for s in segments])
        residues = np.concatenate([model.segments[s].residue_index for s in segments])
        self.n = len(residues)
        self.owner = np.repeat(np.arange(self.n), stops - starts)
        self.rows = np.concatenate([np.arange(a, b) for a, b in zip(starts, stops)])
        top = topology(model.structure)
        backbone = top.backbone
        self.centre = self.start[backbone[residues, 1]]
        self.rotors = side_chain_rotors(model, segments)
        body_of = np.full(len(backbone), -1)
        body_of[residues] = np.arange(self.n)
        k = np.flatnonzero((body_of[top.first] >= 0) & (body_of[top.second] >= 0))
        first, second = top.first[k], top.second[k]
        whole = (backbone[first] >= 0).all(axis=1) & (backbone[second, :2] >= 0).all(axis=1)
        k, first, second = k[whole], first[whole], second[whole]
        ideal_n, ideal_ca = ideal_next(self.start, backbone[first], backbone[second], top.cis[k], top.proline[k])
        self.ideal = np.concatenate([ideal_n, ideal_ca])
        self.ideal_owner = np.concatenate([body_of[first], body_of[first]])
        self.ideal_arm = self.ideal - self.centre[self.ideal_owner]
        self.ideal_on = np.concatenate([backbone[second, 0], backbone[second, 1]])  # the atoms that sit there
        self.size = 6 * self.n + len(self.rotors.bonds)

    def place(self, x: np.ndarray) -> tuple[np.ndarray, ...]:
        """All atom positions (n_atoms, 3) and the ideal points for the unknowns ``x``, and
        what :meth:`gradient` needs."""
        shift = x[: 3 * self.n].reshape(-1, 3)
        rotation = x[3 * self.n : 6 * self.n].reshape(-1, 3) / RADIUS
        turned = self.rotors.turned(self.start, x[6 * self.n :] / RADIUS)
        matrices = Rotation.from_rotvec(rotation).as_matrix()
        arm = turned[self.rows] - self.centre[self.owner]
        coords = self.start.copy()
        coords[self.rows] = self.centre[self.owner] + shift[self.owner] + _apply(matrices[self.owner], arm)
        ideal = (self.centre[self.ideal_owner] + shift[self.ideal_owner]
                 + _apply(matrices[self.ideal_owner], self.ideal_arm))
        return coords, ideal, (rotation, matrices, turned, arm)

    def gradient(self, per_atom: np.ndarray, per_ideal: np.ndarray, placed: tuple) -> np.ndarray:
        """The gradient with respect to the unknowns of a function of the atoms and the
        ideal points whose gradients are ``per_atom`` (n_atoms, 3) and ``per_ideal``."""
        rotation, matrices, turned, arm = placed
        on_body = per_atom[self.rows]
        owners = np.concatenate([self.owner, self.ideal_owner])
        shift = summed_rows(owners, np.concatenate([on_body, per_ideal]), self.n)
        local = _apply_transposed(matrices[self.owner], on_body)  # in each body's start frame
        ideal_local = _apply_transposed(matrices[self.ideal_owner], per_ideal)
        moment = summed_rows(owners, np.concatenate([cross(arm, local), cross(self.ideal_arm, ideal_local)]), self.n)
        turn = np.einsum("bji,bj->bi", _right_jacobian(rotation), moment)
        unturned = np.zeros_like(per_atom)
        unturned[self.rows] = local
        torsion = self.rotors.gradient(turned, unturned)
        return np.concatenate([shift.ravel(), turn.ravel() / RADIUS, torsion / RADIUS])


def refine_real_space(
    model: EditableModel,
    segments: Sequence[int],
    score: Callable[[np.ndarray], tuple[float, np.ndarray]],
    *,
    iterations: int = ITERATIONS,
    cancelled: Callable[[], bool] = lambda: False,
) -> list[Edit]:
    """Move every residue of ``segments`` as a rigid body, its side chains turning, to raise
    ``score`` (of all the model's coordinates: the value and its gradient, as a map's
    correlation) with the junctions held softly and no new overlaps (see the module).
    Returns one edit per segment (not applied; control points unchanged)."""
    bodies = ResidueBodies(model, segments)
    clashes = Clashes(model, bodies.rows)
    best: dict = {"value": -np.inf, "x": np.zeros(bodies.size)}

    def negative(x: np.ndarray) -> tuple[float, np.ndarray]:
        coords, ideal, placed = bodies.place(x)
        value, per_atom = score(coords)
        overlap, push = clashes.penalty(coords)
        off = ideal - coords[bodies.ideal_on]
        objective = value - CLASH_WEIGHT * overlap - JUNCTION_WEIGHT * np.sum(off**2)
        if objective > best["value"]:
            best.update(value=objective, x=x.copy())
        per_atom = per_atom - CLASH_WEIGHT * push
        per_atom += summed_rows(bodies.ideal_on, 2.0 * JUNCTION_WEIGHT * off, len(per_atom))
        return -objective, -bodies.gradient(per_atom, -2.0 * JUNCTION_WEIGHT * off, placed)

    minimize_until_cancelled(negative, best["x"], cancelled, maxiter=iterations)
    coords = bodies.place(best["x"])[0]
    moved = np.zeros(bodies.n, dtype=bool)
    np.logical_or.at(moved, bodies.owner, np.any(coords[bodies.rows] != bodies.start[bodies.rows], axis=1))
    edits, first = [], 0
    for s in segments:
        segment = model.segments[s]
        residues = np.flatnonzero(moved[first : first + len(segment)])
        first += len(segment)
        if len(residues):
            rows = np.concatenate([np.arange(segment.atom_start[r], segment.atom_stop[r]) for r in residues])
            points = model.ribbons[s].points
            edits.append(Edit(s, points, points, residues, rows, bodies.start[rows], coords[rows]))
    return edits


def _apply(matrices: np.ndarray, vectors: np.ndarray) -> np.ndarray:
    return np.einsum("aij,aj->ai", matrices, vectors)


def _apply_transposed(matrices: np.ndarray, vectors: np.ndarray) -> np.ndarray:
    return np.einsum("aji,aj->ai", matrices, vectors)


def _right_jacobian(rotation: np.ndarray) -> np.ndarray:
    """(m, 3, 3) right Jacobians of SO(3) at rotation vectors ``rotation`` (m, 3): the
    derivative of ``R(ω) v`` is ``-R [v]× J_r(ω)``."""
    theta = np.linalg.norm(rotation, axis=1)[:, None, None]
    skew = np.zeros((len(rotation), 3, 3))
    skew[:, 0, 1], skew[:, 0, 2], skew[:, 1, 2] = -rotation[:, 2], rotation[:, 1], -rotation[:, 0]
    skew[:, 1, 0], skew[:, 2, 0], skew[:, 2, 1] = rotation[:, 2], -rotation[:, 1], rotation[:, 0]
    small = theta < 1e-6
    safe = np.where(small, 1.0, theta)
    first = np.where(small, 0.5 - theta**2 / 24, (1.0 - np.cos(safe)) / safe**2)
    second = np.where(small, 1.0 / 6.0 - theta**2 / 120, (safe - np.sin(safe)) / safe**3)
    return np.eye(3) - first * skew + second * skew @ skew
