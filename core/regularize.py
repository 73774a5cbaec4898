"""Regularization after a multiresolution edit: ideal peptide junctions, no new clashes.

Carson's edits move each residue as a rigid body with its curve frame and apply no other
constraint, so peptide bonds stretch and atoms run into each other. Here the residues an
edit moved (plus ``flank`` neighbours on each side) are moved again, each as a rigid body
whose carbonyl O may turn about the Cα–C bond (ψ), to the least-squares best compromise
(Levenberg–Marquardt, analytic Jacobian, sparse normal equations) of the terms below.
Where that leaves something validation would flag, a second fit from there also lets the
side chains that clash turn about their Cα–Cβ bond (χ1).

- **junctions** (σ = :data:`JUNCTION_SIGMA`): each residue carries the ideal planar
  peptide that follows it, built from its own Cα, C and O with Engh & Huber values
  (C–N, Cα–C–N, C–N–Cα; ω = 180°, or 0° where the input peptide is cis); the next
  residue's N and Cα must sit on that peptide's N and Cα. This fixes the bond, both
  angles, ω and the carbonyl planarity and leaves φ and ψ free. Cα-only junctions keep
  their Cα–Cα distance.
- **the tether to the edited curve**: each residue's curve point C^r stays on the curve
  (σ = :data:`TETHER_SIGMA` across it, :data:`SLIDE_SIGMA` along it), and its Cα stays
  near where the edit put it (σ = :data:`HOLD_SIGMA`).
- **torsions**: φ, ψ and χ1 stay near where the edit put them (σ = :data:`TORSION_SIGMA`),
  and a φ or ψ that leaves its allowed Ramachandran region is pulled back to the nearest
  allowed point (σ = :data:`RAMACHANDRAN_SIGMA`).
- **clashes** (σ = :data:`CLASH_SIGMA`, one-sided and smooth): heavy-atom pairs (those
  :mod:`core.validation` checks, and turned atoms against the rest of their residue) are pushed
  apart until they overlap by at most :data:`CLASH_TARGET`, or by what they overlapped
  before the edit if that was more.

Why rigid residues with two turns: the editor moves residues as rigid bodies already,
and 6 parameters per residue, plus a turn about each of two bonds, keep every bond
length and angle inside a residue exact (alternate conformers and hydrogens included)
while the backbone keeps both of its torsions, φ (between residues) and ψ (the carbonyl
turn), to close the junctions and bend around clashes, and a side chain pushed into
others can swing out of the way (χ1; the further side-chain torsions stay as they were).
Side chains turn only in the second fit: most edits settle without them, and each
rotor is one more unknown. The normal equations are sparse and nearly banded (junctions
couple chain neighbours, clashes mostly residues a few apart) and are factored in O(m).
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
from scipy import sparse
from scipy.sparse.linalg import splu
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

from .model import Edit, EditableModel
from .structure import Structure
from .validation import (
    C_N, C_N_CA, C_N_CA_PRO, C_N_PRO, CA_C_N, CA_C_N_PRO, CA_CA_CIS, CA_CA_TRANS, CLASH_OVERLAP, OUTLIER,
    Topology, distance, lengths, nearest_allowed, ramachandran_region, topology,
)  # fmt: skip

FLANK = 3
"""Residues on each side of an edit that may move too (inside the segment)."""
JUNCTION_SIGMA = 0.01
"""Å; the scale of junction residuals (validation tolerates 0.05 Å on the C–N bond)."""
JUNCTION_SLACK = 0.04
"""Å; the solver tries harder while a junction point is off by more than this."""
TETHER_SIGMA = 0.2
"""Å; how far a residue's C^r may leave the edited curve, across it."""
SLIDE_SIGMA = 1.0
"""Å; how far C^r may slide along the curve."""
HOLD_SIGMA = 1.0
"""Å; a weak hold of each Cα where the edit put it."""
TORSION_SIGMA = 15.0
"""Degrees; how far φ, ψ and χ1 may turn from where the edit put them (which keeps
residues in their Ramachandran regions and side chains in their rotamers)."""
RAMACHANDRAN_SIGMA = 0.5
"""Degrees; the scale of a φ's or ψ's distance from the nearest allowed Ramachandran
region (residues that were outliers before the edit are left as they are)."""
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
SKIN = 2.0
"""Å: the clash candidates are the pairs within CLASH_MARGIN + SKIN of clashing, listed
again once the two free atoms that moved most have moved SKIN in all (a Verlet list)."""
DAMPING = 1e-2
"""Initial Levenberg–Marquardt damping, relative to the diagonal."""
STALL = 3e-3
"""Stop when nothing would be flagged, or anyway when a step is predicted to lower the
objective by less than this fraction."""
MAX_ITERATIONS = 25
"""Levenberg–Marquardt steps at most per fit (typically 4–14 are taken; edits that have
not settled by then are over-constrained, and more steps rarely remove a flag)."""
STEP_SHIFT = 1.0
"""Å; no step shifts a body farther, ..."""
STEP_TURN = 20.0
"""Degrees; ... or turns it or its carbonyl farther (the whole step is scaled down): the
clash and Ramachandran terms act only once crossed, so a long step could jump across."""
ROTORS = 2
"""Turns inside a residue: the carbonyl about Cα–C (ψ) and the side chain about Cα–Cβ (χ1)."""
PSI, CHI1, NO_ROTOR = 0, 1, -1
PARAMETERS = 6 + ROTORS
"""Per body: a shift, a rotation vector and the turns of its rotors."""


@dataclass(frozen=True)
class Relaxation:
    """The result of :func:`relax`.

    Attributes
    ----------
    rows : (k,) coordinate rows of the atoms of the free residues, ascending.
    coords : (k, 3) their new positions, Å.
    iterations : Levenberg–Marquardt steps tried.
    cost : final objective, ½ Σ (residual / σ)².
    settled : whether validation would flag nothing the least squares sees.
    """

    rows: np.ndarray
    coords: np.ndarray
    iterations: int
    cost: float
    settled: bool


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


def regularize_region(
    model: EditableModel, segment: int, residues: object, *, flank: int = 0, reference: np.ndarray | None = None
) -> Edit:
    """The edit that regularizes ``residues`` (indices within ``segment``) and up to
    ``flank`` neighbours on each side of the current model, tethered to its current curve
    (control points unchanged). Pairs may keep the overlap they had in ``reference``
    (default: the structure as read)."""
    ribbon = model.ribbons[segment]
    n_residues = len(model.segments[segment])
    residues = np.asarray(residues, dtype=np.int64)
    if residues.ndim != 1 or len(residues) == 0 or residues.min() < 0 or residues.max() >= n_residues:
        raise ValueError(f"residues must be a non-empty list of indices into segment {segment} (0..{n_residues - 1})")
    free = _with_flanks(residues, flank, n_residues)
    u = ribbon.residue_u[free]
    anchors = ribbon.space.evaluate(ribbon.points, u)
    tangents = ribbon.space.evaluate(ribbon.points, u, 1)
    reference = model.structure.coords if reference is None else reference
    result = relax(model.structure, model.coords, model.segments[segment].residue_index[free], anchors, tangents,
                   reference)
    return Edit(segment, ribbon.points, ribbon.points, free, result.rows, model.coords[result.rows], result.coords)


def relax(
    structure: Structure,
    coords: np.ndarray,
    residues: np.ndarray,
    anchors: np.ndarray,
    tangents: np.ndarray,
    reference: np.ndarray | None = None,
) -> Relaxation:
    """Move ``residues`` (rigid, turning carbonyls and clashing side chains) to ideal
    junctions, on the curve, without new clashes.

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
        return Relaxation(np.zeros(0, dtype=np.int64), np.zeros((0, 3)), 0, 0.0, True)
    anchors, tangents = np.asarray(anchors, float), np.asarray(tangents, float)
    backbone = _Problem(structure, coords, residues, anchors, tangents, reference, side_chains=False).solve()
    if backbone.settled:
        return backbone
    # something would still be flagged: side chains that clash may turn too (χ1), from here
    start = coords.copy()
    start[backbone.rows] = backbone.coords
    problem = _Problem(structure, start, residues, anchors, tangents, reference, side_chains=True)
    if not problem.axis[:, CHI1].any():  # no side chain clashes: nothing new to try
        return backbone
    result = problem.solve()
    return Relaxation(result.rows, result.coords, backbone.iterations + result.iterations, result.cost, result.settled)


def _with_flanks(residues: np.ndarray, flank: int, n_residues: int) -> np.ndarray:
    """``residues`` and up to ``flank`` neighbours on each side, within ``0..n_residues-1``."""
    if flank < 0:
        raise ValueError(f"flank must be >= 0; got {flank}")
    spread = (np.asarray(residues, dtype=np.int64)[:, None] + np.arange(-flank, flank + 1)).ravel()
    return np.unique(spread[(spread >= 0) & (spread < n_residues)])


# ---------------------------------------------------------------------------- solver


@dataclass(frozen=True)
class _State:
    """Where the bodies are: body ``k`` turned by ``rotation[k]`` about its start Cα and
    moved by ``shift[k]``, its carbonyl and side chain turned first by ``turn[k]`` (ψ about
    the Cα–C bond, χ1 about the Cα–Cβ bond)."""

    rotation: np.ndarray
    shift: np.ndarray
    turn: np.ndarray

    @classmethod
    def start(cls, n_bodies: int) -> _State:
        return cls(np.broadcast_to(np.eye(3), (n_bodies, 3, 3)).copy(), np.zeros((n_bodies, 3)),
                   np.zeros((n_bodies, ROTORS)))

    def moved(self, step: np.ndarray) -> _State:
        """The state after ``step``: (m, PARAMETERS) of (δt, δω, δψ, δχ1) per body."""
        turn = Rotation.from_rotvec(step[:, 3:6]).as_matrix()
        return _State(np.einsum("bij,bjk->bik", turn, self.rotation), self.shift + step[:, :3], self.turn + step[:, 6:])


class _Problem:
    """The free residues as bodies and the terms of the least squares.

    A point ``y`` of body ``k`` (residue ``residues[k]``) moves to ``c + t + R (y' - c)``,
    ``c`` the body's start Cα, where ``y' = y`` but for the carbonyl (O, OXT and the ideal
    next N and Cα built on them), first turned by ψ about the start Cα–C axis, and a
    clashing side chain beyond Cβ, first turned by χ1 about the start Cα–Cβ axis. The
    unknowns are 6 per body and one per rotor it has (:attr:`column`).
    Points of the terms belong to a body or to none (-1: fixed). A vector term weighs the
    difference of two points with a 3 x 3 matrix (one residual per row); distance terms
    ask two points to be ``d0`` apart; Ramachandran terms a φ or ψ to be allowed; clash
    terms two atoms to be at least ``d_min`` apart. Residuals come in that order.
    """

    def __init__(self, structure: Structure, coords: np.ndarray, residues: np.ndarray,
                 anchors: np.ndarray, tangents: np.ndarray, reference: np.ndarray, side_chains: bool) -> None:
        top = topology(structure)
        self.reference = reference
        self.n_bodies = n = len(residues)
        bb = top.backbone
        body_of = np.full(len(bb), -1)
        body_of[residues] = np.arange(n)
        self.atom_body = np.where(structure.atom_residue >= 0, body_of[structure.atom_residue.clip(min=0)], -1)
        self.rows = np.flatnonzero(self.atom_body >= 0)
        self.top = top = top.around(self.rows)  # every clash pair has a free atom
        self.centre = coords[bb[residues, 1]]
        self.pivot, self.axis, self.atom_rotor = _rotors(structure, coords, residues, self.atom_body, bb, top, side_chains)
        rotor = np.any(self.axis != 0, axis=2)  # (n, ROTORS): which bodies have which rotor
        present = np.concatenate([np.ones((n, 6), dtype=bool), rotor], axis=1)
        self.column = np.where(present, np.cumsum(present).reshape(n, PARAMETERS) - 1, -1)
        self.n_columns = int(present.sum())
        self.current = coords.copy()
        self.free_atoms = self.rows[top.checked[self.rows]]
        self.surroundings: np.ndarray | None = None
        self.listed_at: np.ndarray | None = None
        points, owners, rotors, vector_terms = [], [], [], []

        def add(xyz: np.ndarray, owner: np.ndarray, on: int = NO_ROTOR) -> np.ndarray:
            """Points ``xyz`` of bodies ``owner``, turned by their rotor ``on`` (where they have it)."""
            start = sum(len(p) for p in points)
            points.append(xyz)
            owners.append(owner)
            turned = (owner >= 0) & rotor[owner, on] if on != NO_ROTOR else np.zeros(len(xyz), dtype=bool)
            rotors.append(np.where(turned, on, NO_ROTOR))
            return np.arange(start, start + len(xyz))

        def coincide(a: tuple, b: tuple, weights: np.ndarray) -> None:
            vector_terms.append((add(*a), add(*b), np.broadcast_to(weights, (len(a[0]), 3, 3))))

        # junctions with a free residue: the next N and Cα on this residue's ideal peptide
        k = np.flatnonzero((body_of[top.first] >= 0) | (body_of[top.second] >= 0))
        first, second = top.first[k], top.second[k]
        full = (bb[first, 1:4] >= 0).all(axis=1) & (bb[second, :2] >= 0).all(axis=1)
        before, after = first[full], second[full]
        ideal_n, ideal_ca = _ideal_next(coords, bb[before], bb[after], top.cis[k[full]], top.proline[k[full]])
        stiff = np.eye(3) / JUNCTION_SIGMA
        coincide((ideal_n, body_of[before], PSI), (coords[bb[after, 0]], body_of[after]), stiff)
        coincide((ideal_ca, body_of[before], PSI), (coords[bb[after, 1]], body_of[after]), stiff)
        self.n_junction_rows = 6 * len(before)  # the first rows: N and Cα of the next residue, 3 each
        f, s = first[~full], second[~full]  # Cα only: keep the Cα–Cα distance
        self.distance_a = add(coords[bb[f, 1]], body_of[f])
        self.distance_b = add(coords[bb[s, 1]], body_of[s])
        self.distance_d0 = np.where(top.cis[k[~full]], CA_CA_CIS, CA_CA_TRANS)
        self._ramachandran_terms(residues, body_of, reference)
        # the tether: C^r on the curve (free to slide along it), Cα near where it was
        along = _unit(tangents)
        weights = np.concatenate([_normal_planes(along) / TETHER_SIGMA, along[:, None] / SLIDE_SIGMA], axis=1)
        coincide((anchors, np.full(n, -1)), (anchors, np.arange(n)), weights)
        coincide((self.centre, np.full(n, -1)), (self.centre, np.arange(n)), np.eye(3) / HOLD_SIGMA)
        # torsions held loosely (each a turn of a point about a bond, 2 r sin(angle / 2) long):
        # ψ and χ1, the first heavy atom each rotor turns against the same atom unturned; φ, each C
        # on its residue against the same C on the carbonyl before it
        for on in (PSI, CHI1):
            rows = self.free_atoms[self.atom_rotor[self.free_atoms] == on]
            body, first_row = np.unique(self.atom_body[rows], return_index=True)
            atom = coords[rows[first_row]]
            radius = _off_axis(atom, self.pivot[body, on], self.axis[body, on])
            coincide((atom, body), (atom, body, on), _torsion_weights(radius))
        ok = bb[after, 2] >= 0
        before, after = before[ok], after[ok]
        carbon = coords[bb[after, 2]]
        radius = _off_axis(carbon, coords[bb[after, 1]], _unit(coords[bb[after, 1]] - coords[bb[after, 0]]))
        coincide((carbon, body_of[before], PSI), (carbon, body_of[after]), _torsion_weights(radius))
        vector_a, vector_b, weights = (np.concatenate(t) for t in zip(*vector_terms))
        self.vector_a, self.vector_b, self.vector_weights = vector_a, vector_b, weights
        self.n_vector_rows = 3 * len(vector_a)
        # every point that may move: the points of the terms, then the atoms of the free residues
        self.n_points = sum(len(p) for p in points)
        self.start = np.concatenate([*points, coords[self.rows]])
        owner = np.concatenate([*owners, self.atom_body[self.rows]])
        rotor_of = np.concatenate([*rotors, self.atom_rotor[self.rows]])
        self.moving = np.flatnonzero(owner >= 0)
        self.moving_body = owner[self.moving]
        self.turning = np.flatnonzero(rotor_of != NO_ROTOR)
        self.turning_body, self.turning_rotor = owner[self.turning], rotor_of[self.turning]
        # the two sides of the vector rows (3 per term) and distance terms: points, bodies, rotors
        side_a = np.concatenate([np.repeat(vector_a, 3), self.distance_a])
        side_b = np.concatenate([np.repeat(vector_b, 3), self.distance_b])
        self.sides = tuple((side, owner[side], rotor_of[side]) for side in (side_a, side_b))
        self.vector_direction = weights.reshape(-1, 3)

    def _ramachandran_terms(self, residues: np.ndarray, body_of: np.ndarray, reference: np.ndarray) -> None:
        """φ (its outer atom: the C before) and ψ (the N after) of the free residues that
        were not Ramachandran outliers in ``reference``. A row pairs the outer atom, on its
        own residue, with the same atom carried rigidly by the residue whose angle it is:
        the angle changes with the difference of the two."""
        top, bb = self.top, self.top.backbone
        before, after = np.full(len(bb), -1), np.full(len(bb), -1)
        before[top.second], after[top.first] = top.first, top.second
        prev, next_ = before[residues], after[residues]
        c_before = np.where(prev >= 0, bb[prev, 2], -1)
        n_after = np.where(next_ >= 0, bb[next_, 0], -1)
        chain = np.column_stack([c_before, bb[residues, :3], n_after])
        kind = top.rama_class[residues]
        p = reference[chain].transpose(1, 0, 2)
        with np.errstate(invalid="ignore", divide="ignore"):  # rows with a missing atom are dropped below
            angles = np.degrees([_dihedrals(*p[:4])[0], _dihedrals(*p[1:])[0]])
        region = ramachandran_region(np.nan_to_num(angles[0]), np.nan_to_num(angles[1]), kind)
        k = np.flatnonzero((chain >= 0).all(axis=1) & (region != OUTLIER))
        self.rama_atoms, self.rama_kind = chain[k], kind[k]
        self.rama_owners = np.concatenate([k, k]), np.concatenate([body_of[prev[k]], body_of[next_[k]]])

    def ramachandran(self, current: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """How far each φ and ψ is from the nearest allowed Ramachandran region (radians / σ;
        the φ rows, then the ψ rows; 0 where allowed), the gradients of those residuals with
        respect to the outer atoms, and where those atoms are."""
        p = current[self.rama_atoms]
        # φ of C-N-Cα-C and ψ of N-Cα-C-N: the φ rows, then the ψ rows
        angle, first, last = _dihedrals(*np.concatenate([p[:, :4], p[:, 1:]]).transpose(1, 0, 2))
        m = len(p)
        degrees = np.degrees(angle)
        target = np.concatenate(nearest_allowed(degrees[:m], degrees[m:], self.rama_kind))
        off = np.where(target != degrees, (angle - np.radians(target) + np.pi) % (2 * np.pi) - np.pi, 0.0)
        sigma = np.radians(RAMACHANDRAN_SIGMA)
        gradient = np.concatenate([first[:m], last[m:]]) * ((off != 0) / sigma)[:, None]
        return off / sigma, gradient, np.concatenate([p[:, 0], p[:, 4]])

    def place(self, state: _State) -> np.ndarray:
        """Positions at ``state`` of the term points, then of the atoms of the free residues."""
        out = self.start.copy()
        k, on = self.turning_body, self.turning_rotor
        pivot = self.pivot[k, on]
        out[self.turning] = pivot + _turned(out[self.turning] - pivot, self.axis[k, on], state.turn[k, on])
        b = self.moving_body
        centre = self.centre[b]
        turned = np.einsum("aij,aj->ai", state.rotation[b], out[self.moving] - centre)
        out[self.moving] = centre + state.shift[b] + turned
        return out

    def atoms(self, state: _State, placed: np.ndarray | None = None) -> np.ndarray:
        """All atom positions with the free residues at ``state`` (one buffer, rewritten by
        every call); ``placed``: :meth:`place` of ``state`` if known."""
        self.current[self.rows] = (self.place(state) if placed is None else placed)[self.n_points :]
        return self.current

    def clash_pairs(self, current: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Pairs with a free atom within CLASH_MARGIN of clashing, and the distance each
        should keep: its contact distance less CLASH_TARGET, or its distance before."""
        moving = current[self.free_atoms]
        if self.listed_at is None or _list_expired(moving, self.listed_at):
            self._list_candidates(current)
        i, j = self.candidate_i, self.candidate_j
        near = distance(current[i], current[j]) < self.candidate_limit
        return i[near], j[near], self.candidate_d_min[near]

    def _list_candidates(self, current: np.ndarray) -> None:
        """The pairs that may clash until two free atoms have moved SKIN in all from here
        (a Verlet list), with their clash limit and the distance each should keep."""
        reach = CLASH_TARGET - CLASH_MARGIN
        cutoff = self.top.search_radius(reach) + SKIN
        moving = current[self.free_atoms]
        if self.surroundings is None or np.any(moving < self.box[0]) or np.any(moving > self.box[1]):
            self.box = moving.min(axis=0) - SURROUNDINGS, moving.max(axis=0) + SURROUNDINGS
            low, high = self.box[0] - cutoff, self.box[1] + cutoff
            fixed = np.flatnonzero(self.top.checked & (self.atom_body < 0))
            self.surroundings = fixed[np.all((current[fixed] >= low) & (current[fixed] <= high), axis=1)]
            self.surroundings_tree = cKDTree(current[self.surroundings])
        tree = cKDTree(moving)
        inner = tree.query_pairs(cutoff, output_type="ndarray")
        outer = tree.sparse_distance_matrix(self.surroundings_tree, cutoff, output_type="ndarray")
        i = np.concatenate([self.free_atoms[inner[:, 0]], self.free_atoms[outer["i"]]])
        j = np.concatenate([self.free_atoms[inner[:, 1]], self.surroundings[outer["j"]]])
        i, j = np.minimum(i, j), np.maximum(i, j)
        keep = (self.atom_body[i] != self.atom_body[j]) | (self.atom_rotor[i] != self.atom_rotor[j])
        i, j = self.top.screen(current, i[keep], j[keep], reach - SKIN)
        contact = self.top.contact(i, j)
        self.candidate_i, self.candidate_j, self.candidate_limit = i, j, contact - reach
        self.candidate_d_min = np.minimum(contact - CLASH_TARGET, distance(self.reference[i], self.reference[j]))
        self.listed_at = moving

    def violated(self, residual: np.ndarray) -> bool:
        """Whether validation could still flag a junction (a point of it off by more than
        JUNCTION_SLACK), a residue (a Ramachandran outlier) or a clash (a pair overlapping
        by more than CLASH_OVERLAP)."""
        start = self.n_vector_rows
        stop = start + len(self.distance_d0)
        junction = np.abs(np.concatenate([residual[: self.n_junction_rows], residual[start:stop]])) * JUNCTION_SIGMA
        rama = residual[stop : stop + 2 * len(self.rama_atoms)]
        clash = residual[stop + len(rama) :] * CLASH_SIGMA
        return bool(np.any(junction > JUNCTION_SLACK) or np.any(rama != 0)
                    or np.any(clash < CLASH_TARGET - CLASH_OVERLAP))

    def evaluate(self, state: _State) -> tuple[np.ndarray, tuple]:
        """Residuals at ``state``, and what :meth:`jacobian` needs to differentiate them."""
        x = self.place(state)
        current = self.atoms(state, x)
        # vector terms: W (x_b - x_a), one residual per row of W
        vector_residual = np.einsum("kij,kj->ki", self.vector_weights, x[self.vector_b] - x[self.vector_a]).ravel()
        # distance terms (|x_b - x_a| - d0) / σ; clash terms softplus(d_min - |x_b - x_a|) / σ
        i, j, d_min = self.clash_pairs(current)
        n_distance = len(self.distance_d0)
        pair_a = np.concatenate([x[self.distance_a], current[i]])
        vector = np.concatenate([x[self.distance_b], current[j]]) - pair_a
        sigma = np.concatenate([np.full(n_distance, JUNCTION_SIGMA), np.full(len(i), CLASH_SIGMA)])
        length = lengths(vector)
        gap = length - np.concatenate([self.distance_d0, d_min])
        value, slope = gap.copy(), np.ones(len(gap))
        z = -gap[n_distance:] / CLASH_SOFTNESS
        value[n_distance:] = -CLASH_SOFTNESS * np.logaddexp(0.0, z)
        slope[n_distance:] = 1.0 / (1.0 + np.exp(-z))
        unit = (slope / sigma)[:, None] * vector / np.maximum(length, 1e-12)[:, None]
        rama, rama_direction, outer = self.ramachandran(current)
        residual = np.concatenate([vector_residual, value[:n_distance] / sigma[:n_distance], rama,
                                   value[n_distance:] / sigma[n_distance:]])
        no_turn = np.full(len(outer), NO_ROTOR)
        sides = tuple(
            (np.concatenate([x[points], outer, current[atoms]]),
             np.concatenate([owner, rama_owner, self.atom_body[atoms]]),
             np.concatenate([on, no_turn, self.atom_rotor[atoms]]))
            for (points, owner, on), rama_owner, atoms in zip(self.sides, self.rama_owners, (i, j))
        )
        direction = np.concatenate([self.vector_direction, unit[:n_distance], rama_direction, unit[n_distance:]])
        return residual, (*sides, direction, state)

    def jacobian(self, terms: tuple) -> sparse.csr_matrix:
        """The Jacobian of the residuals with respect to (δt, δω, δψ, δχ1) of every body.

        To first order each residual is ``d . x_b - d . x_a``, and for a point ``x`` of a
        body with Cα at ``c``, turned by a rotor of axis ``a`` through ``p``,
        ``d(d . x)/d(δt, δω, δturn) = (d, (x - c) x d, a . ((x - p) x d))``, the last in the
        column of that rotor only. Each row has the entries of each moving side.
        """
        (xa, oa, ra), (xb, ob, rb), direction, state = terms
        centre = self.centre + state.shift
        axis = np.einsum("bij,brj->bri", state.rotation, self.axis)
        pivot = centre[:, None] + np.einsum("bij,brj->bri", state.rotation, self.pivot - self.centre[:, None])
        n = len(direction)
        xyz, owner, on = np.concatenate([xa, xb]), np.concatenate([oa, ob]), np.concatenate([ra, rb])
        body, rotor = np.maximum(owner, 0), np.maximum(on, 0)
        both = np.concatenate([-direction, direction])  # x_a enters with a minus sign
        block = np.empty((2 * n, PARAMETERS))
        block[:, :3] = both
        block[:, 3:6] = _cross(xyz - centre[body], both)
        block[:, 6:] = np.einsum("ij,ij->i", axis[body, rotor], _cross(xyz - pivot[body, rotor], both))[:, None]
        mask = np.repeat((owner >= 0)[:, None], PARAMETERS, axis=1)
        mask[:, 6:] &= on[:, None] == np.arange(ROTORS)  # (where a body has a rotor, it has its column)
        # row k of the Jacobian: the entries of side a, then of side b
        mask = mask.reshape(2, n, PARAMETERS).transpose(1, 0, 2)
        data = block.reshape(2, n, PARAMETERS).transpose(1, 0, 2)[mask]
        columns = self.column[body].reshape(2, n, PARAMETERS).transpose(1, 0, 2)
        indptr = np.concatenate([[0], np.cumsum(mask.sum(axis=(1, 2)))])
        return sparse.csr_matrix((data, columns[mask], indptr), shape=(n, self.n_columns))

    def per_body(self, step: np.ndarray) -> np.ndarray:
        """(m, PARAMETERS) parameters of every body from the unknowns ``step`` (0 for rotors
        a body lacks)."""
        out = np.zeros((self.n_bodies, PARAMETERS))
        present = self.column >= 0
        out[present] = step[self.column[present]]
        return out

    def solve(self) -> Relaxation:
        """Levenberg–Marquardt from the start positions."""
        state = _State.start(self.n_bodies)
        residual, terms = self.evaluate(state)
        jacobian = self.jacobian(terms)
        normal = _Normal(jacobian)
        cost = 0.5 * residual @ residual
        damping, growth = DAMPING, 2.0
        iterations = 0
        for iterations in range(1, MAX_ITERATIONS + 1):
            step = -normal.solve(jacobian.T @ residual, damping)
            per_body = self.per_body(step)
            reach = max(np.abs(per_body[:, :3]).max() / STEP_SHIFT,
                        np.abs(per_body[:, 3:]).max() / np.radians(STEP_TURN))
            limited = reach > 1.0
            if limited:
                step /= reach
                per_body /= reach
            predicted = cost - 0.5 * np.sum((residual + jacobian @ step) ** 2)
            trial = state.moved(per_body)
            trial_residual, terms = self.evaluate(trial)
            trial_cost = 0.5 * trial_residual @ trial_residual
            if trial_cost < cost:
                gain = (cost - trial_cost) / max(predicted, 1e-300)
                state, residual, cost = trial, trial_residual, trial_cost
                jacobian = self.jacobian(terms)
                normal = _Normal(jacobian)
                damping = max(damping * max(1 / 3, 1 - (2 * gain - 1) ** 3), 1e-7)
                growth = 2.0
                if not limited and (not self.violated(residual) or predicted < STALL * cost):
                    break
            else:  # the same normal matrix, damped more
                damping *= growth
                growth *= 2
        return Relaxation(self.rows, self.atoms(state)[self.rows].copy(), iterations, float(cost),
                          not self.violated(residual))


class _Normal:
    """The normal matrix ``J^T J`` of a Jacobian, to solve ``(J^T J + λ D) δ = g`` for
    several dampings λ (D its diagonal).

    Bodies are residues in chain order: junctions couple neighbouring bodies and most
    clash pairs residues a few apart, so the matrix is sparse and nearly banded; SuperLU
    (a fill-reducing order, no pivoting: it is positive definite) factors it in O(m).
    """

    def __init__(self, jacobian: sparse.csr_matrix) -> None:
        self.matrix = (jacobian.T @ jacobian).tocsc()  # symmetric: its CSR arrays are its CSC arrays
        self.matrix.sum_duplicates()  # sorted indices (splu would sort the arrays in place)
        column = np.repeat(np.arange(self.matrix.shape[1]), np.diff(self.matrix.indptr))
        self.diagonal = np.flatnonzero(self.matrix.indices == column)  # every unknown has terms: all are there
        self.values = self.matrix.data.copy()

    def solve(self, gradient: np.ndarray, damping: float) -> np.ndarray:
        """``δ`` for the damping λ = ``damping``."""
        data = self.matrix.data
        data[:] = self.values
        data[self.diagonal] *= 1.0 + damping
        data[self.diagonal] += 1e-12 * data[self.diagonal].max()
        factor = splu(self.matrix, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True})
        return factor.solve(gradient)


def _normal_planes(along: np.ndarray) -> np.ndarray:
    """(m, 2, 3) two unit vectors perpendicular to each unit vector of ``along`` (m, 3)."""
    helper = np.eye(3)[np.argmin(np.abs(along), axis=1)]
    first = _cross(along, helper)
    first /= lengths(first)[:, None]
    return np.stack([first, _cross(along, first)], axis=1)


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


def _list_expired(now: np.ndarray, then: np.ndarray) -> bool:
    """Whether a pair left out of a Verlet list made at ``then`` (k, 3 free atoms) may have
    come within its cutoff at ``now``: the two largest moves add up to more than SKIN (a
    pair with a fixed atom has only one move)."""
    return bool(np.sort(lengths(now - then))[-2:].sum() > SKIN)


def _unit(v: np.ndarray) -> np.ndarray:
    return v / lengths(v)[:, None]


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise cross products of (k, 3) arrays (``np.cross`` costs more for short arrays)."""
    a0, a1, a2 = a[:, 0], a[:, 1], a[:, 2]
    b0, b1, b2 = b[:, 0], b[:, 1], b[:, 2]
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    out[:, 0], out[:, 1], out[:, 2] = a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0
    return out


def _dihedrals(a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray) -> tuple[np.ndarray, ...]:
    """Dihedral angles a–b–c–d (radians; rows of (k, 3) arrays, as
    :func:`core.validation.dihedral`) and their gradients (per Å) with respect to a and d."""
    b1, b2, b3 = b - a, c - b, d - c
    n1, n2 = _cross(b1, b2), _cross(b2, b3)
    length = lengths(b2)
    angle = np.arctan2(length * np.einsum("ij,ij->i", b1, n2), np.einsum("ij,ij->i", n1, n2))
    first = -length[:, None] * n1 / np.einsum("ij,ij->i", n1, n1)[:, None]
    last = length[:, None] * n2 / np.einsum("ij,ij->i", n2, n2)[:, None]
    return angle, first, last


_MAIN_CHAIN = ("N", "CA", "C", "O", "OXT", "CB", "H", "H1", "H2", "H3", "HA", "HA2", "HA3", "HN", "HXT")
"""Atom names that χ1 leaves in place (Cβ lies on its axis)."""


def _rotors(
    structure: Structure, coords: np.ndarray, residues: np.ndarray, atom_body: np.ndarray, bb: np.ndarray,
    top: Topology, side_chains: bool,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The rotors of the bodies: (m, ROTORS, 3) pivots and unit axes (zero where a body has
    no such rotor), and the rotor that turns each atom (NO_ROTOR for all others).

    ψ turns O and OXT about Cα–C; with ``side_chains``, χ1 turns everything beyond Cβ about
    Cα–Cβ for side chains that overlap another atom by more than CLASH_TARGET at the start
    (not proline, whose ring closes on N): only those need to move, and each rotor costs
    an unknown."""
    n = len(residues)
    names = structure.atoms.name
    atom_rotor = np.full(len(coords), NO_ROTOR)
    rows = np.flatnonzero(atom_body >= 0)
    beta = np.full(n, -1)
    is_beta = names[rows] == "CB"
    beta[atom_body[rows[is_beta]]] = rows[is_beta]
    bonds = np.stack([bb[residues, 2], beta], axis=1)  # the far atom of each rotor's bond
    bonds[structure.atoms.resname[bb[residues, 1]] == "PRO", CHI1] = -1
    body = atom_body[rows]
    carbonyl = np.isin(names[rows], ("O", "OXT"))
    side_chain = ~np.isin(names[rows], _MAIN_CHAIN) & top.checked[rows]
    clashing = np.unique(np.concatenate(top.close_pairs(coords, rows[side_chain & side_chains], CLASH_TARGET)))
    has = bonds >= 0
    has[:, PSI] &= np.isin(np.arange(n), body[carbonyl])
    has[:, CHI1] &= np.isin(np.arange(n), atom_body[clashing[np.isin(clashing, rows[side_chain])]])
    centre = coords[bb[residues, 1]]
    pivot = np.where(has[..., None], coords[bonds], centre[:, None])
    axis = np.zeros((n, ROTORS, 3))
    axis[has] = _unit(pivot[has] - np.broadcast_to(centre[:, None], pivot.shape)[has])
    atom_rotor[rows[carbonyl & has[body, PSI]]] = PSI
    atom_rotor[rows[~np.isin(names[rows], _MAIN_CHAIN) & has[body, CHI1]]] = CHI1
    return pivot, axis, atom_rotor


def _off_axis(points: np.ndarray, through: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """Distances (Å) of ``points`` from the lines through ``through`` along unit ``axis`` (all (k, 3))."""
    arm = points - through
    return lengths(arm - np.einsum("ij,ij->i", arm, axis)[:, None] * axis)


def _torsion_weights(radius: np.ndarray) -> np.ndarray:
    """(k, 3, 3) weights that make a point ``radius`` Å off a bond, turned about it, a
    residual of about (turn / TORSION_SIGMA) per row."""
    return np.eye(3) / (np.radians(TORSION_SIGMA) * radius)[:, None, None]


def _turned(v: np.ndarray, axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Vectors ``v`` (k, 3) turned by ``angle`` (k,) about unit vectors ``axis`` (k, 3) (Rodrigues)."""
    cos, sin = np.cos(angle)[:, None], np.sin(angle)[:, None]
    return v * cos + _cross(axis, v) * sin + axis * np.einsum("ij,ij->i", axis, v)[:, None] * (1.0 - cos)
