"""The least-squares terms of regularization (see :mod:`core.geometry.regularize`): the free
residues as rigid bodies with rotors, and the residuals and analytic Jacobian of the
junction, tether, torsion, Ramachandran and clash terms, for
:func:`core.geometry.least_squares.levenberg_marquardt`."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse
from scipy.spatial.transform import Rotation

from core.geometry.clash_list import CLASH_TARGET, ClashList
from core.geometry.ideal import (
    C_N,
    C_N_CA,
    C_N_CA_PRO,
    C_N_PRO,
    CA_C_N,
    CA_C_N_PRO,
    CA_CA_CIS,
    CA_CA_TRANS,
    CLASH_OVERLAP,
)
from core.geometry.ramachandran import OUTLIER, nearest_allowed, ramachandran_region
from core.geometry.topology import Topology, topology
from core.geometry.vectors import cross, dihedral_gradients, distance, lengths, off_axis, turned, unit
from core.protein.structure import Structure

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
CLASH_SOFTNESS = 0.05
"""Å; a clash residual is ``-s log(1 + exp(-gap / s))``: smooth, so that a step sees
pairs about to clash, and about ``-gap`` once they do."""
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
class BodyState:
    """Where the bodies are: body ``k`` turned by ``rotation[k]`` about its start Cα and
    moved by ``shift[k]``, its carbonyl and side chain turned first by ``turn[k]`` (ψ about
    the Cα–C bond, χ1 about the Cα–Cβ bond)."""

    rotation: np.ndarray
    shift: np.ndarray
    turn: np.ndarray

    @classmethod
    def start(cls, n_bodies: int) -> BodyState:
        """Every body where it is."""
        return cls(np.broadcast_to(np.eye(3), (n_bodies, 3, 3)).copy(), np.zeros((n_bodies, 3)),
                   np.zeros((n_bodies, ROTORS)))

    def moved(self, step: np.ndarray) -> BodyState:
        """The state after ``step``: (m, PARAMETERS) of (δt, δω, δψ, δχ1) per body."""
        turn = Rotation.from_rotvec(step[:, 3:6]).as_matrix()
        return BodyState(np.einsum("bij,bjk->bik", turn, self.rotation), self.shift + step[:, :3], self.turn + step[:, 6:])


class Restraints:
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
    ``softness`` multiplies the σ of the stiff terms (junctions, clashes, Ramachandran), for
    a relaxation that starts loose and tightens (:func:`core.geometry.regularize.relax`);
    ``held`` (m, 3) is where each Cα is held (default: where it is).
    """

    def __init__(self, structure: Structure, coords: np.ndarray, residues: np.ndarray,
                 anchors: np.ndarray, tangents: np.ndarray, reference: np.ndarray, side_chains: bool,
                 softness: float = 1.0, held: np.ndarray | None = None) -> None:
        top = topology(structure)
        self.junction_sigma = JUNCTION_SIGMA * softness
        self.clash_sigma = CLASH_SIGMA * softness
        self.ramachandran_sigma = RAMACHANDRAN_SIGMA * softness
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
        self.clashes = ClashList(top, self.atom_body, self.atom_rotor, self.free_atoms, reference)
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
        ideal_n, ideal_ca = ideal_next(coords, bb[before], bb[after], top.cis[k[full]], top.proline[k[full]])
        stiff = np.eye(3) / self.junction_sigma
        coincide((ideal_n, body_of[before], PSI), (coords[bb[after, 0]], body_of[after]), stiff)
        coincide((ideal_ca, body_of[before], PSI), (coords[bb[after, 1]], body_of[after]), stiff)
        self.n_junction_rows = 6 * len(before)  # the first rows: N and Cα of the next residue, 3 each
        f, s = first[~full], second[~full]  # Cα only: keep the Cα–Cα distance
        self.distance_a = add(coords[bb[f, 1]], body_of[f])
        self.distance_b = add(coords[bb[s, 1]], body_of[s])
        self.distance_d0 = np.where(top.cis[k[~full]], CA_CA_CIS, CA_CA_TRANS)
        self._ramachandran_terms(residues, body_of, reference)
        # the tether: C^r on the curve (free to slide along it), Cα near where it was
        along = unit(tangents)
        weights = np.concatenate([_normal_planes(along) / TETHER_SIGMA, along[:, None] / SLIDE_SIGMA], axis=1)
        coincide((anchors, np.full(n, -1)), (anchors, np.arange(n)), weights)
        held = self.centre if held is None else held
        coincide((held, np.full(n, -1)), (self.centre, np.arange(n)), np.eye(3) / HOLD_SIGMA)
        # torsions held loosely (each a turn of a point about a bond, 2 r sin(angle / 2) long):
        # ψ and χ1, the first heavy atom each rotor turns against the same atom unturned; φ, each C
        # on its residue against the same C on the carbonyl before it
        for on in (PSI, CHI1):
            rows = self.free_atoms[self.atom_rotor[self.free_atoms] == on]
            body, first_row = np.unique(self.atom_body[rows], return_index=True)
            atom = coords[rows[first_row]]
            radius = off_axis(atom, self.pivot[body, on], self.axis[body, on])
            coincide((atom, body), (atom, body, on), _torsion_weights(radius))
        ok = bb[after, 2] >= 0
        before, after = before[ok], after[ok]
        carbon = coords[bb[after, 2]]
        radius = off_axis(carbon, coords[bb[after, 1]], unit(coords[bb[after, 1]] - coords[bb[after, 0]]))
        coincide((carbon, body_of[before], PSI), (carbon, body_of[after]), _torsion_weights(radius))
        vector_a, vector_b, weights = (np.concatenate(t) for t in zip(*vector_terms))
        self.vector_a, self.vector_b, self.vector_weights = vector_a, vector_b, weights
        self.n_vector_rows = 3 * len(vector_a)
        # every point that may move: the points of the terms, then the atoms of the free residues
        self.n_points = sum(len(p) for p in points)
        self.start_points = np.concatenate([*points, coords[self.rows]])
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
            angles = np.degrees([dihedral_gradients(*p[:4])[0], dihedral_gradients(*p[1:])[0]])
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
        angle, first, last = dihedral_gradients(*np.concatenate([p[:, :4], p[:, 1:]]).transpose(1, 0, 2))
        m = len(p)
        degrees = np.degrees(angle)
        target = np.concatenate(nearest_allowed(degrees[:m], degrees[m:], self.rama_kind))
        off = np.where(target != degrees, (angle - np.radians(target) + np.pi) % (2 * np.pi) - np.pi, 0.0)
        sigma = np.radians(self.ramachandran_sigma)
        gradient = np.concatenate([first[:m], last[m:]]) * ((off != 0) / sigma)[:, None]
        return off / sigma, gradient, np.concatenate([p[:, 0], p[:, 4]])

    def place(self, state: BodyState) -> np.ndarray:
        """Positions at ``state`` of the term points, then of the atoms of the free residues."""
        out = self.start_points.copy()
        k, on = self.turning_body, self.turning_rotor
        pivot = self.pivot[k, on]
        out[self.turning] = pivot + turned(out[self.turning] - pivot, self.axis[k, on], state.turn[k, on])
        b = self.moving_body
        centre = self.centre[b]
        rotated = np.einsum("aij,aj->ai", state.rotation[b], out[self.moving] - centre)
        out[self.moving] = centre + state.shift[b] + rotated
        return out

    def atoms(self, state: BodyState, placed: np.ndarray | None = None) -> np.ndarray:
        """All atom positions with the free residues at ``state`` (one buffer, rewritten by
        every call); ``placed``: :meth:`place` of ``state`` if known."""
        self.current[self.rows] = (self.place(state) if placed is None else placed)[self.n_points :]
        return self.current

    def violated(self, residual: np.ndarray) -> bool:
        """Whether validation could still flag a junction (a point of it off by more than
        JUNCTION_SLACK), a residue (a Ramachandran outlier) or a clash (a pair overlapping
        by more than CLASH_OVERLAP)."""
        start = self.n_vector_rows
        stop = start + len(self.distance_d0)
        junction = np.abs(np.concatenate([residual[: self.n_junction_rows], residual[start:stop]]))
        junction *= self.junction_sigma
        rama = residual[stop : stop + 2 * len(self.rama_atoms)]
        clash = residual[stop + len(rama) :] * self.clash_sigma
        return bool(np.any(junction > JUNCTION_SLACK) or np.any(rama != 0)
                    or np.any(clash < CLASH_TARGET - CLASH_OVERLAP))

    def evaluate(self, state: BodyState) -> tuple[np.ndarray, tuple]:
        """Residuals at ``state``, and what :meth:`jacobian` needs to differentiate them."""
        x = self.place(state)
        current = self.atoms(state, x)
        # vector terms: W (x_b - x_a), one residual per row of W
        vector_residual = np.einsum("kij,kj->ki", self.vector_weights, x[self.vector_b] - x[self.vector_a]).ravel()
        # distance terms (|x_b - x_a| - d0) / σ; clash terms softplus(d_min - |x_b - x_a|) / σ
        i, j, d_min = self.clashes.pairs(current)
        n_distance = len(self.distance_d0)
        pair_a = np.concatenate([x[self.distance_a], current[i]])
        vector = np.concatenate([x[self.distance_b], current[j]]) - pair_a
        sigma = np.concatenate([np.full(n_distance, self.junction_sigma), np.full(len(i), self.clash_sigma)])
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
        block[:, 3:6] = cross(xyz - centre[body], both)
        block[:, 6:] = np.einsum("ij,ij->i", axis[body, rotor], cross(xyz - pivot[body, rotor], both))[:, None]
        mask = np.repeat((owner >= 0)[:, None], PARAMETERS, axis=1)
        mask[:, 6:] &= on[:, None] == np.arange(ROTORS)  # (where a body has a rotor, it has its column)
        # row k of the Jacobian: the entries of side a, then of side b
        mask = mask.reshape(2, n, PARAMETERS).transpose(1, 0, 2)
        data = block.reshape(2, n, PARAMETERS).transpose(1, 0, 2)[mask]
        columns = self.column[body].reshape(2, n, PARAMETERS).transpose(1, 0, 2)
        indptr = np.concatenate([[0], np.cumsum(mask.sum(axis=(1, 2)))])
        return sparse.csr_matrix((data, columns[mask], indptr), shape=(n, self.n_columns))

    def start(self) -> BodyState:
        """Every body where it is."""
        return BodyState.start(self.n_bodies)

    def reach(self, per_body: np.ndarray) -> float:
        """How many times STEP_SHIFT or STEP_TURN the longest move of a step is."""
        return max(np.abs(per_body[:, :3]).max() / STEP_SHIFT, np.abs(per_body[:, 3:]).max() / np.radians(STEP_TURN))

    def per_body(self, step: np.ndarray) -> np.ndarray:
        """(m, PARAMETERS) parameters of every body from the unknowns ``step`` (0 for rotors
        a body lacks)."""
        out = np.zeros((self.n_bodies, PARAMETERS))
        present = self.column >= 0
        out[present] = step[self.column[present]]
        return out


def _normal_planes(along: np.ndarray) -> np.ndarray:
    """(m, 2, 3) two unit vectors perpendicular to each unit vector of ``along`` (m, 3)."""
    helper = np.eye(3)[np.argmin(np.abs(along), axis=1)]
    first = cross(along, helper)
    first /= lengths(first)[:, None]
    return np.stack([first, cross(along, first)], axis=1)


def ideal_next(
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
    u = unit(ca - c)  # C -> Cα
    v = unit(o - c - np.einsum("ij,ij->i", o - c, u)[:, None] * u)  # in plane, towards O
    n = c + c_n[:, None] * (np.cos(ca_c_n)[:, None] * u - np.sin(ca_c_n)[:, None] * v)
    e = unit(c - n)  # N -> C
    towards_ca = unit(ca - c - np.einsum("ij,ij->i", ca - c, e)[:, None] * e)
    side = np.where(cis, 1.0, -1.0)[:, None]  # trans: the next Cα opposite the previous one
    next_ca = n + n_ca[:, None] * (np.cos(c_n_ca)[:, None] * e + side * np.sin(c_n_ca)[:, None] * towards_ca)
    return n, next_ca


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
    axis[has] = unit(pivot[has] - np.broadcast_to(centre[:, None], pivot.shape)[has])
    atom_rotor[rows[carbonyl & has[body, PSI]]] = PSI
    atom_rotor[rows[~np.isin(names[rows], _MAIN_CHAIN) & has[body, CHI1]]] = CHI1
    return pivot, axis, atom_rotor


def _torsion_weights(radius: np.ndarray) -> np.ndarray:
    """(k, 3, 3) weights that make a point ``radius`` Å off a bond, turned about it, a
    residual of about (turn / TORSION_SIGMA) per row."""
    return np.eye(3) / (np.radians(TORSION_SIGMA) * radius)[:, None, None]
