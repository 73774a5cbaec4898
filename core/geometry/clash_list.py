"""The atom pairs that may clash while some atoms move: a Verlet list for regularization.

Pairs with a free atom are listed once with a margin (:data:`SKIN`) and listed again only
when the free atoms have moved far enough that a pair left out could have come close; the
fixed atoms near the free ones are found once for moves up to :data:`SURROUNDINGS`.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from core.geometry.topology import Topology
from core.geometry.vectors import distance, lengths

CLASH_TARGET = 0.3
"""Å of overlap at which pairs are pushed apart (validation flags 0.4 Å)."""
CLASH_MARGIN = 0.5
"""Å: pairs this much short of clashing enter the least squares."""
SURROUNDINGS = 4.0
"""Å: the fixed atoms near the free ones are found once, for moves up to this far."""
SKIN = 2.0
"""Å: the clash candidates are the pairs within CLASH_MARGIN + SKIN of clashing, listed
again once the two free atoms that moved most have moved SKIN in all (a Verlet list)."""


class ClashList:
    """Candidate clash pairs of the ``free_atoms`` (checked atom rows), against each other
    and the fixed atoms, kept up to date as they move.

    Parameters
    ----------
    top : the topology (radii, bonded pairs).
    atom_body : (n_atoms,) the body of each atom, -1 for fixed atoms.
    atom_rotor : (n_atoms,) the rotor that turns each atom within its body (pairs on one
        body and rotor never change distance, so they are left out).
    free_atoms : rows of the atoms that move and are checked.
    reference : (n_atoms, 3) positions before the edit: pairs may keep the overlap they had.
    """

    def __init__(self, top: Topology, atom_body: np.ndarray, atom_rotor: np.ndarray, free_atoms: np.ndarray,
                 reference: np.ndarray) -> None:
        self.top, self.atom_body, self.atom_rotor = top, atom_body, atom_rotor
        self.free_atoms, self.reference = free_atoms, reference
        self.surroundings: np.ndarray | None = None
        self.listed_at: np.ndarray | None = None

    def pairs(self, current: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Pairs with a free atom within CLASH_MARGIN of clashing at ``current`` (all atom
        positions), and the distance each should keep: its contact distance less
        CLASH_TARGET, or its distance before."""
        moving = current[self.free_atoms]
        if self.listed_at is None or _list_expired(moving, self.listed_at):
            self._list(current)
        i, j = self.candidate_i, self.candidate_j
        near = distance(current[i], current[j]) < self.candidate_limit
        return i[near], j[near], self.candidate_d_min[near]

    def _list(self, current: np.ndarray) -> None:
        """The pairs that may clash until two free atoms have moved SKIN in all from here,
        with their clash limit and the distance each should keep."""
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


def _list_expired(now: np.ndarray, then: np.ndarray) -> bool:
    """Whether a pair left out of a Verlet list made at ``then`` (k, 3 free atoms) may have
    come within its cutoff at ``now``: the two largest moves add up to more than SKIN (a
    pair with a fixed atom has only one move)."""
    return bool(np.sort(lengths(now - then))[-2:].sum() > SKIN)
