"""Regularization after a multiresolution edit: ideal peptide junctions, no new clashes.

Carson's edits move each residue as a rigid body with its curve frame and apply no other
constraint, so peptide bonds stretch and atoms run into each other. Here the residues an
edit moved (plus ``flank`` neighbours on each side) are moved again, each still as a
rigid body, to the least-squares best compromise (Levenberg–Marquardt on the rigid-body
motions, analytic Jacobian, sparse normal equations) of:

- **junctions** (σ = :data:`JUNCTION_SIGMA`): each residue carries the ideal planar
  peptide that follows it, built from its own Cα, C and O with Engh & Huber values
  (C–N, Cα–C–N, C–N–Cα; ω = 180°, or 0° where the input peptide is cis); the next
  residue's N and Cα must sit on that peptide's N and Cα. With rigid residues this fixes
  the bond, both angles, ω and the carbonyl planarity and leaves φ free; ψ and the side
  chains keep the conformation they had. Cα-only junctions keep their Cα–Cα distance.
- **the tether to the edited curve**: each residue's curve point C^r stays on the curve
  (σ = :data:`TETHER_SIGMA` across it, :data:`SLIDE_SIGMA` along it), and its N, Cα and C
  stay near where the edit put them (σ = :data:`ORIENTATION_SIGMA`).
- **clashes** (σ = :data:`CLASH_SIGMA`, one-sided and smooth): heavy-atom pairs (those
  :mod:`core.validation` checks) are pushed apart until they overlap by at most
  :data:`CLASH_TARGET`, or by what they overlapped before the edit if that was more.

Why rigid residues: the editor moves residues as rigid bodies already; 6 parameters per
residue keep every bond inside a residue exact (side chains, rotamers, alternate
conformers, hydrogens), and the normal equations are sparse and nearly banded (junctions
couple chain neighbours), solved by preconditioned conjugate gradients in O(m). The price is that ψ cannot change, so the chain bends at
φ only; tight bends that need ψ are met less closely by the tether.
Why fixed outer neighbours: the edit's B-spline change fades to zero at the ends of its
support, so the rest of the chain is left exactly as it was (locality, nothing to redraw
outside the edit), and the ``flank`` residues just inside absorb the strain at the two
outer junctions.

:func:`regularized` turns an :class:`~core.model.Edit` into the regularized edit (same
segment, same old state, so undo stays exact); :func:`regularize_region` regularizes any
stretch of residues of the current model; :func:`relax` is the array-level solver.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import linalg, sparse
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

from .model import Edit, EditableModel
from .structure import Structure
from .validation import (
    C_N, C_N_CA, C_N_CA_PRO, C_N_PRO, CA_C_N, CA_C_N_PRO, CA_CA_CIS, CA_CA_TRANS, distance, topology,
)  # fmt: skip

FLANK = 3
"""Residues on each side of an edit that may move too (inside the segment)."""
JUNCTION_SIGMA = 0.01
"""Å; the scale of junction residuals (validation tolerates 0.05 Å on the C–N bond)."""
TETHER_SIGMA = 0.2
"""Å; how far a residue's C^r may leave the edited curve, across it."""
SLIDE_SIGMA = 1.0
"""Å; how far C^r may slide along the curve."""
ORIENTATION_SIGMA = 1.0
"""Å; a weak hold of N, Cα and C where the edit put them (the residue's orientation)."""
CLASH_SIGMA = 0.01
"""Å; the scale of clash residuals."""
CLASH_TARGET = 0.3
"""Å of overlap at which pairs are pushed apart (validation flags 0.4 Å)."""
CLASH_SOFTNESS = 0.05
"""Å; a clash residual is ``-s log(1 + exp(-gap / s))``: smooth, so that a step sees
pairs about to clash, and about ``-gap`` once they do."""
CLASH_MARGIN = 0.5
"""Å: pairs this much short of clashing enter the least squares."""
SURROUNDINGS = 4.0
"""Å: the fixed atoms near the free ones are found once, for moves up to this far."""
DAMPING = 1e-2
"""Initial Levenberg–Marquardt damping, relative to the diagonal."""
TOLERANCE = 3e-2
"""Stop when a step is predicted to lower the objective by less than this fraction (a
tenth of it while a junction or a clash is still out of tolerance)."""
MAX_ITERATIONS = 40
"""Levenberg–Marquardt steps at most (typically 8–20 are taken)."""
BAND_BLOCKS = 4
"""Width, in 6 x 6 blocks below the diagonal, of the band that preconditions the solve."""
CG_STEPS = 50
"""Conjugate-gradient steps at most per solve."""
CG_TOLERANCE = 1e-6
"""Stop the conjugate gradients when r·M⁻¹r has fallen by this factor (an inexact step is
as good to Levenberg–Marquardt)."""


@dataclass(frozen=True)
class Relaxation:
    """The result of :func:`relax`.

    Attributes
    ----------
    rows : (k,) coordinate rows of the atoms of the free residues, ascending.
    coords : (k, 3) their new positions, Å.
    iterations : Levenberg–Marquardt steps tried.
    cost : final objective, ½ Σ (residual / σ)².
    """

    rows: np.ndarray
    coords: np.ndarray
    iterations: int
    cost: float


def regularized(model: EditableModel, edit: Edit, *, flank: int = FLANK) -> Edit:
    """The edit ``edit`` followed by regularization, as one :class:`Edit`.

    ``model`` may hold ``edit``'s old or new state (only ``edit.rows`` differ between the
    two). The result has the same segment, control points and old state; its residues and
    rows add up to ``flank`` neighbours on each side, so undo restores everything.
    """
    segment = model.segments[edit.segment]
    ribbon = model.ribbons[edit.segment]
    free = _with_flanks(edit.residues, flank, len(segment))
    before = model.coords.copy()
    before[edit.rows] = edit.old_coords
    after = before.copy()
    after[edit.rows] = edit.new_coords
    u = ribbon.residue_u[free]
    anchors = ribbon.space.evaluate(edit.new_points, u)
    tangents = ribbon.space.evaluate(edit.new_points, u, 1)
    result = relax(model.structure, after, segment.residue_index[free], anchors, tangents, before)
    return Edit(edit.segment, edit.old_points, edit.new_points, free, result.rows, before[result.rows], result.coords)


def regularize_region(model: EditableModel, segment: int, residues: object, *, flank: int = 0) -> Edit:
    """The edit that regularizes ``residues`` (indices within ``segment``) of the current
    model, tethered to its current curve (control points unchanged)."""
    ribbon = model.ribbons[segment]
    n_residues = len(model.segments[segment])
    residues = np.asarray(residues, dtype=np.int64)
    if residues.ndim != 1 or len(residues) == 0 or residues.min() < 0 or residues.max() >= n_residues:
        raise ValueError(f"residues must be a non-empty list of indices into segment {segment} (0..{n_residues - 1})")
    free = _with_flanks(residues, flank, n_residues)
    u = ribbon.residue_u[free]
    anchors = ribbon.space.evaluate(ribbon.points, u)
    tangents = ribbon.space.evaluate(ribbon.points, u, 1)
    result = relax(model.structure, model.coords, model.segments[segment].residue_index[free], anchors, tangents)
    return Edit(segment, ribbon.points, ribbon.points, free, result.rows, model.coords[result.rows], result.coords)


def relax(
    structure: Structure,
    coords: np.ndarray,
    residues: np.ndarray,
    anchors: np.ndarray,
    tangents: np.ndarray,
    reference: np.ndarray | None = None,
) -> Relaxation:
    """Move ``residues`` as rigid bodies to ideal junctions, on the curve, without new clashes.

    Parameters
    ----------
    structure : the structure (backbone atoms, bonds, radii, cis peptides).
    coords : (n_atoms, 3) start positions, Å (e.g. with an edit applied).
    residues : (m,) residue-table rows that may move; every other atom stays fixed.
    anchors : (m, 3) the curve point C^r of each, where the residue sits on the curve, Å.
    tangents : (m, 3) curve tangents there (any length).
    reference : (n_atoms, 3) positions before the edit: pairs that overlapped there may
        keep that overlap (default: ``coords``).

    Returns
    -------
    Relaxation
    """
    coords = np.asarray(coords, dtype=np.float64)
    reference = coords if reference is None else np.asarray(reference, dtype=np.float64)
    residues = np.asarray(residues, dtype=np.int64)
    if coords.shape != structure.coords.shape or reference.shape != coords.shape:
        raise ValueError(f"coords and reference must have shape {structure.coords.shape}")
    for name, array in (("anchors", anchors), ("tangents", tangents)):
        if np.shape(array) != (len(residues), 3):
            raise ValueError(f"{name} must have shape ({len(residues)}, 3); got {np.shape(array)}")
    if len(residues) == 0:
        return Relaxation(np.zeros(0, dtype=np.int64), np.zeros((0, 3)), 0, 0.0)
    return _Problem(structure, coords, residues, np.asarray(anchors, float), np.asarray(tangents, float), reference).solve()


def _with_flanks(residues: np.ndarray, flank: int, n_residues: int) -> np.ndarray:
    """``residues`` and up to ``flank`` neighbours on each side, within ``0..n_residues-1``."""
    if flank < 0:
        raise ValueError(f"flank must be >= 0; got {flank}")
    spread = (np.asarray(residues, dtype=np.int64)[:, None] + np.arange(-flank, flank + 1)).ravel()
    return np.unique(spread[(spread >= 0) & (spread < n_residues)])


# ---------------------------------------------------------------------------- solver


class _Problem:
    """The free residues as rigid bodies and the terms of the least squares.

    Every point is attached to a body (or to nothing: fixed) and moves as
    ``x = c + t + R (x0 - c)``, ``c`` the body's Cα at the start. A vector term weighs the
    difference of two points with a 3 x 3 matrix (one residual per row); distance terms
    ask two points to be ``d0`` apart; clash terms two atoms to be at least ``d_min`` apart.
    """

    def __init__(self, structure: Structure, coords: np.ndarray, residues: np.ndarray,
                 anchors: np.ndarray, tangents: np.ndarray, reference: np.ndarray) -> None:
        self.top = top = topology(structure)
        self.coords = coords
        self.reference = reference
        body_of = np.full(len(top.backbone), -1)
        body_of[residues] = np.arange(len(residues))
        self.body_of_atom = np.where(structure.atom_residue >= 0, body_of[structure.atom_residue.clip(min=0)], -1)
        self.rows = np.flatnonzero(self.body_of_atom >= 0)
        self.free_atoms = self.rows[top.checked[self.rows]]
        self.surroundings: np.ndarray | None = None
        self.centres = coords[top.backbone[residues, 1]]
        self.n_bodies = n = len(residues)
        points, owners, vector_terms = [], [], []

        def add(xyz: np.ndarray, owner: np.ndarray) -> np.ndarray:
            start = sum(len(p) for p in points)
            points.append(xyz)
            owners.append(owner)
            return np.arange(start, start + len(xyz))

        def coincide(xyz_a: np.ndarray, owner_a: np.ndarray, xyz_b: np.ndarray, owner_b: np.ndarray,
                     weights: np.ndarray) -> None:
            weights = np.broadcast_to(weights, (len(xyz_a), 3, 3))
            vector_terms.append((add(xyz_a, owner_a), add(xyz_b, owner_b), weights))

        # junctions with a free residue: the next N and Cα on this residue's ideal peptide
        k = np.flatnonzero((body_of[top.first] >= 0) | (body_of[top.second] >= 0))
        first, second, bb = top.first[k], top.second[k], top.backbone
        full = (bb[first, 1:4] >= 0).all(axis=1) & (bb[second, :2] >= 0).all(axis=1)
        f, s = first[full], second[full]
        ideal_n, ideal_ca = _ideal_next(coords, bb[f], bb[s], top.cis[k[full]], top.proline[k[full]])
        stiff = np.eye(3) / JUNCTION_SIGMA
        coincide(ideal_n, body_of[f], coords[bb[s, 0]], body_of[s], stiff)
        coincide(ideal_ca, body_of[f], coords[bb[s, 1]], body_of[s], stiff)
        self.n_junction_rows = 6 * len(f)  # the first rows: N and Cα of the next residue, 3 each
        f, s = first[~full], second[~full]  # Cα only: keep the Cα–Cα distance
        self.distance_a = add(coords[bb[f, 1]], body_of[f])
        self.distance_b = add(coords[bb[s, 1]], body_of[s])
        self.distance_d0 = np.where(top.cis[k[~full]], CA_CA_CIS, CA_CA_TRANS)
        # the tether: C^r on the curve (free to slide along it), N, Cα, C near where they were
        along = tangents / np.linalg.norm(tangents, axis=1, keepdims=True)
        across = _normal_planes(along)
        weights = np.concatenate([across / TETHER_SIGMA, along[:, None] / SLIDE_SIGMA], axis=1)
        coincide(anchors, np.full(n, -1), anchors, np.arange(n), weights)
        held = bb[residues, :3]
        body, slot = np.nonzero(held >= 0)
        targets = coords[held[body, slot]]
        coincide(targets, np.full(len(body), -1), targets, body, np.eye(3) / ORIENTATION_SIGMA)

        self.points0 = np.concatenate(points)
        self.owner = np.concatenate(owners)
        self.vector_a, self.vector_b, self.vector_weights = (np.concatenate(t) for t in zip(*vector_terms))

    def place(self, xyz: np.ndarray, owner: np.ndarray, rotation: np.ndarray, shift: np.ndarray) -> np.ndarray:
        """Positions of start points ``xyz`` attached to bodies ``owner`` (-1: fixed)."""
        out = xyz.copy()
        moving = owner >= 0
        b = owner[moving]
        out[moving] = self.centres[b] + shift[b] + np.einsum("aij,aj->ai", rotation[b], xyz[moving] - self.centres[b])
        return out

    def atoms(self, rotation: np.ndarray, shift: np.ndarray) -> np.ndarray:
        """All atom positions with the free residues moved."""
        current = self.coords.copy()
        current[self.rows] = self.place(self.coords[self.rows], self.body_of_atom[self.rows], rotation, shift)
        return current

    def clash_pairs(self, current: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Pairs with a free atom within CLASH_MARGIN of clashing, and the distance each
        should keep: its contact distance less CLASH_TARGET, or its distance before."""
        reach = CLASH_TARGET - CLASH_MARGIN
        cutoff = self.top.search_radius(reach)
        moving = current[self.free_atoms]
        if self.surroundings is None or np.any(moving < self.box[0]) or np.any(moving > self.box[1]):
            self._surround(current, cutoff)
        tree = cKDTree(moving)
        inner = tree.query_pairs(cutoff, output_type="ndarray")
        outer = tree.sparse_distance_matrix(self.surroundings_tree, cutoff, output_type="ndarray")
        i = np.concatenate([self.free_atoms[inner[:, 0]], self.free_atoms[outer["i"]]])
        j = np.concatenate([self.free_atoms[inner[:, 1]], self.surroundings[outer["j"]]])
        i, j = np.minimum(i, j), np.maximum(i, j)
        keep = self.body_of_atom[i] != self.body_of_atom[j]
        i, j = self.top.screen(current, i[keep], j[keep], reach)
        d_min = np.minimum(self.top.contact(i, j) - CLASH_TARGET, distance(self.reference[i], self.reference[j]))
        return i, j, d_min

    def _surround(self, current: np.ndarray, cutoff: float) -> None:
        """The fixed atoms near the free ones (a tree, kept while the free atoms stay in a box)."""
        moving = current[self.free_atoms]
        self.box = moving.min(axis=0) - SURROUNDINGS, moving.max(axis=0) + SURROUNDINGS
        low, high = self.box[0] - cutoff, self.box[1] + cutoff
        fixed = np.flatnonzero(self.top.checked & (self.body_of_atom < 0))
        self.surroundings = fixed[np.all((current[fixed] >= low) & (current[fixed] <= high), axis=1)]
        self.surroundings_tree = cKDTree(current[self.surroundings])

    def violated(self, residual: np.ndarray) -> bool:
        """Whether a junction is off by more than 0.02 Å or a pair overlaps by more than 0.4 Å."""
        junction = np.abs(residual[: self.n_junction_rows]) * JUNCTION_SIGMA
        start = len(self.vector_a) * 3
        distance_rows = np.abs(residual[start : start + len(self.distance_d0)]) * JUNCTION_SIGMA
        clash = residual[start + len(self.distance_d0) :] * CLASH_SIGMA
        return bool(np.any(junction > 0.02) or np.any(distance_rows > 0.02) or np.any(clash < CLASH_TARGET - 0.4))

    def evaluate(self, rotation: np.ndarray, shift: np.ndarray) -> tuple[np.ndarray, tuple]:
        """Residuals, and what :meth:`jacobian` needs to differentiate them."""
        x = self.place(self.points0, self.owner, rotation, shift)
        current = self.atoms(rotation, shift)
        # vector terms: W (x_b - x_a), one residual per row of W
        a, b = np.repeat(self.vector_a, 3), np.repeat(self.vector_b, 3)
        vector_residual = np.einsum("kij,kj->ki", self.vector_weights, x[self.vector_b] - x[self.vector_a]).ravel()
        # distance terms (|x_b - x_a| - d0) / σ; clash terms softplus(d_min - |x_b - x_a|) / σ
        i, j, d_min = self.clash_pairs(current)
        pair_a = np.concatenate([x[self.distance_a], current[i]])
        pair_b = np.concatenate([x[self.distance_b], current[j]])
        n_distance = len(self.distance_d0)
        sigma = np.concatenate([np.full(n_distance, JUNCTION_SIGMA), np.full(len(i), CLASH_SIGMA)])
        vector = pair_b - pair_a
        length = np.linalg.norm(vector, axis=1)
        gap = length - np.concatenate([self.distance_d0, d_min])
        value, slope = gap.copy(), np.ones(len(gap))
        z = -gap[n_distance:] / CLASH_SOFTNESS
        value[n_distance:] = -CLASH_SOFTNESS * np.logaddexp(0.0, z)
        slope[n_distance:] = 1.0 / (1.0 + np.exp(-z))
        unit = (slope / sigma)[:, None] * vector / np.maximum(length, 1e-12)[:, None]
        residual = np.concatenate([vector_residual, value / sigma])
        direction = np.concatenate([self.vector_weights.reshape(-1, 3), unit])
        xa, xb = np.concatenate([x[a], pair_a]), np.concatenate([x[b], pair_b])
        oa = np.concatenate([self.owner[a], self.owner[self.distance_a], self.body_of_atom[i]])
        ob = np.concatenate([self.owner[b], self.owner[self.distance_b], self.body_of_atom[j]])
        return residual, (xa, xb, oa, ob, direction, self.centres + shift)

    def jacobian(self, terms: tuple) -> sparse.csr_matrix:
        """The Jacobian of the residuals with respect to (δt, δω) of every body: each residual
        is ``direction . x_b - direction . x_a`` to first order, and
        ``d(direction . x)/d(δt, δω) = (direction, (x - c) x direction)`` for the body of x."""
        xa, xb, oa, ob, direction, centre = terms
        rows, cols, vals = [], [], []
        for xyz, owner, sign in ((xb, ob, 1.0), (xa, oa, -1.0)):
            moving = np.flatnonzero(owner >= 0)
            body = owner[moving]
            lever = np.cross(xyz[moving] - centre[body], direction[moving])
            rows.append(np.repeat(moving, 6))
            cols.append((6 * body[:, None] + np.arange(6)).ravel())
            vals.append(sign * np.concatenate([direction[moving], lever], axis=1).ravel())
        return sparse.csr_matrix(
            (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(len(direction), 6 * self.n_bodies)
        )

    def solve(self) -> Relaxation:
        """Levenberg–Marquardt from the start positions."""
        rotation = np.broadcast_to(np.eye(3), (self.n_bodies, 3, 3)).copy()
        shift = np.zeros((self.n_bodies, 3))
        residual, terms = self.evaluate(rotation, shift)
        jacobian = self.jacobian(terms)
        cost = 0.5 * residual @ residual
        damping = DAMPING
        iterations = 0
        for iterations in range(1, MAX_ITERATIONS + 1):
            step = -_solve_normal(jacobian, residual, damping)
            predicted = cost - 0.5 * np.sum((residual + jacobian @ step) ** 2)
            trial = _moved(rotation, shift, step)
            trial_residual, terms = self.evaluate(*trial)
            trial_cost = 0.5 * trial_residual @ trial_residual
            if trial_cost < cost:
                (rotation, shift), residual, jacobian, cost = trial, trial_residual, self.jacobian(terms), trial_cost
                damping = max(damping / 3, 1e-7)
                if predicted < TOLERANCE * cost and (predicted < 0.1 * TOLERANCE * cost or not self.violated(residual)):
                    break
            else:
                damping *= 4
        return Relaxation(self.rows, self.atoms(rotation, shift)[self.rows], iterations, float(cost))


def _solve_normal(jacobian: sparse.csr_matrix, residual: np.ndarray, damping: float) -> np.ndarray:
    """Solve the damped normal equations ``(J^T J + λ D) δ = J^T r`` (D its diagonal).

    Bodies are residues in chain order: junctions couple neighbouring bodies and most
    clash pairs residues a few apart (i, i+3 and i+4 in helices), so the matrix of 6 x 6
    blocks is banded but for a few blocks of residues in contact across the fold.
    Conjugate gradients, preconditioned with the banded Cholesky factor of its band of
    BAND_BLOCKS blocks, converge in a few steps of O(m) each.
    """
    normal = (jacobian.T @ jacobian).tocsr()
    diagonal = normal.diagonal()
    damped = (1.0 + damping) * diagonal + 1e-12 * diagonal.max()
    entries = normal.tocoo()
    lower = (entries.row > entries.col) & (entries.row // 6 - entries.col // 6 <= BAND_BLOCKS)
    band = np.zeros((6 * BAND_BLOCKS + 6, len(damped)))
    band[entries.row[lower] - entries.col[lower], entries.col[lower]] = entries.data[lower]
    band[0] = damped
    factor, info = linalg.lapack.dpbtrf(band, lower=1)
    if info:
        raise np.linalg.LinAlgError("normal equations are not positive definite")

    def multiply(v: np.ndarray) -> np.ndarray:
        return normal @ v + (damped - diagonal) * v

    def precondition(v: np.ndarray) -> np.ndarray:
        return linalg.lapack.dpbtrs(factor, v, lower=1)[0]

    b = jacobian.T @ residual
    x = precondition(b)
    z0 = x.copy()
    r = b - multiply(x)
    z = precondition(r)
    p = z
    rz = r @ z
    for _ in range(CG_STEPS):
        if rz <= CG_TOLERANCE * (b @ z0):
            break
        q = multiply(p)
        alpha = rz / (p @ q)
        x += alpha * p
        r -= alpha * q
        z = precondition(r)
        rz, rz_old = r @ z, rz
        p = z + (rz / rz_old) * p
    return x


def _moved(rotation: np.ndarray, shift: np.ndarray, step: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rotations and shifts after the step ``step``, (δt, δω) per body flattened."""
    step = step.reshape(-1, 6)
    return np.einsum("bij,bjk->bik", Rotation.from_rotvec(step[:, 3:]).as_matrix(), rotation), shift + step[:, :3]


def _normal_planes(along: np.ndarray) -> np.ndarray:
    """(m, 2, 3) two unit vectors perpendicular to each unit vector of ``along`` (m, 3)."""
    helper = np.eye(3)[np.argmin(np.abs(along), axis=1)]
    first = np.cross(along, helper)
    first /= np.linalg.norm(first, axis=1, keepdims=True)
    return np.stack([first, np.cross(along, first)], axis=1)


def _ideal_next(
    coords: np.ndarray, here: np.ndarray, after: np.ndarray, cis: np.ndarray, proline: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Ideal N and Cα of the residue after each junction, from this residue's Cα, C, O.

    ``here`` and ``after`` are (k, 4) backbone rows (N, Cα, C, O) of the two residues; the
    Cα of the next residue keeps its own N–Cα length. Returns two (k, 3) arrays.
    """
    ca, c, o = coords[here[:, 1]], coords[here[:, 2]], coords[here[:, 3]]
    n_ca = distance(coords[after[:, 0]], coords[after[:, 1]])
    c_n = np.where(proline, C_N_PRO, C_N)
    ca_c_n = np.radians(np.where(proline, CA_C_N_PRO, CA_C_N))
    c_n_ca = np.radians(np.where(proline, C_N_CA_PRO, C_N_CA))
    u = _unit(ca - c)  # C -> Cα
    v = _unit(o - c - np.einsum("ij,ij->i", o - c, u)[:, None] * u)  # in plane, towards O
    n = c + c_n[:, None] * (np.cos(ca_c_n)[:, None] * u - np.sin(ca_c_n)[:, None] * v)
    e = _unit(c - n)  # N -> C
    towards_ca = _unit(ca - c - np.einsum("ij,ij->i", ca - c, e)[:, None] * e)
    side = np.where(cis, 1.0, -1.0)[:, None]  # trans: the next Cα opposite the previous one
    next_ca = n + n_ca[:, None] * (np.cos(c_n_ca)[:, None] * e + side * np.sin(c_n_ca)[:, None] * towards_ca)
    return n, next_ca


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=1, keepdims=True)
