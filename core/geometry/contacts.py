"""Polar contacts: the nitrogen and oxygen atoms of two residues or groups close enough for a
hydrogen bond (2.5 to 3.5 Å between donor and acceptor), as PyMOL's *find polar contacts*
and ChimeraX's ``contacts`` show them around a binding site. By distance, less the pairs the
backbone rules out: two amide nitrogens (donors only), two carbonyl oxygens (acceptors
only), a proline's nitrogen (neither), and the nitrogens bound to a metal (neither: a haem's
four and its histidine's, whose lone pairs the iron holds); so of side chains and ligands,
whose hydrogens a crystal structure seldom gives, a pair of two acceptors may be listed too.
The bonds of metal ions to the atoms around them are listed apart (:func:`metal_bonds`)."""

from __future__ import annotations

import gemmi
import numpy as np
from scipy.spatial import cKDTree

from core.protein.structure import AtomTable

POLAR_REACH = 3.5
"""Å: the farthest a donor and an acceptor of a hydrogen bond are apart."""
CLOSEST = 2.5
"""Å: nearer than this, two atoms are bonded or clash, not hydrogen-bonded."""
METAL_BOND = 2.6
"""Å: a nitrogen this near a metal is bound to it (Fe, Zn, Cu or Mg to N: 2.0-2.2 Å)."""
METAL_REACH = 3.1
"""Å: the farthest a metal ion and an N, O or S atom it binds are apart (Zn-N 2.1, Ca-O 2.4 to 3.1)."""


def polar_contacts(atoms: AtomTable, coords: np.ndarray, chosen: np.ndarray, reach: float = POLAR_REACH,
                   *, among: bool = True) -> np.ndarray:
    """(k, 2) coordinate rows of the polar contacts of the atoms ``chosen`` (rows): pairs of a
    chosen N or O atom and an N or O atom of another residue or group (not water, no N bound
    to a metal; with ``among`` False, not chosen either) :data:`CLOSEST` to ``reach`` Å from
    it, on ``coords``; the first alternate conformer only, each pair once, the lower row
    first, in increasing order."""
    element = np.char.upper(atoms.element.astype(str))
    proline_n = (atoms.category == "protein") & (atoms.resname == "PRO") & (atoms.name == "N")
    polar = np.flatnonzero(np.isin(element, ("N", "O")) & (atoms.category != "water") & ~proline_n
                           & np.isin(atoms.altloc, ("", "A")))
    metals = _metals(atoms, element)
    if len(metals) and len(polar):  # the nitrogens a metal holds
        bound = cKDTree(coords[metals]).query(coords[polar], distance_upper_bound=METAL_BOND)[0] <= METAL_BOND
        polar = polar[~(bound & (element[polar] == "N"))]
    first, second = _near(atoms, coords, np.intersect1d(polar, chosen), polar, reach)
    backbone = np.where(atoms.category == "protein", atoms.name, "")
    kind = np.select([backbone == "N", np.isin(backbone, ("O", "OXT"))], ["donor", "acceptor"], "")
    keep = ((np.linalg.norm(coords[first] - coords[second], axis=1) >= CLOSEST)
            & ((kind[first] == "") | (kind[first] != kind[second])))
    if not among:
        keep &= ~np.isin(second, chosen)
    return _pairs(first[keep], second[keep])


def metal_bonds(atoms: AtomTable, coords: np.ndarray, chosen: np.ndarray) -> np.ndarray:
    """(k, 2) coordinate rows of the bonds of metal ions to the N, O and S atoms around them
    (waters' too) within :data:`METAL_REACH` Å, on ``coords``, a metal or the atom it binds
    among ``chosen``, as ChimeraX draws a site's metal coordination; the first alternate
    conformer only, each pair once, the lower row first, in increasing order."""
    element = np.char.upper(atoms.element.astype(str))
    first_conformer = np.isin(atoms.altloc, ("", "A"))
    metals = _metals(atoms, element)
    metals = metals[first_conformer[metals]]
    binding = np.flatnonzero(np.isin(element, ("N", "O", "S")) & first_conformer)
    found = [_near(atoms, coords, np.intersect1d(metals, chosen), binding, METAL_REACH),
             _near(atoms, coords, np.intersect1d(binding, chosen), metals, METAL_REACH)]
    return _pairs(np.concatenate([found[0][0], found[1][0]]), np.concatenate([found[0][1], found[1][1]]))


def _metals(atoms: AtomTable, element: np.ndarray) -> np.ndarray:
    """The rows of the metal atoms (gemmi's elements: Fe, Zn, Mg, Ca, Na, ...)."""
    return np.flatnonzero(np.isin(element, [e for e in np.unique(element) if e and gemmi.Element(e).is_metal]))


def _near(atoms: AtomTable, coords: np.ndarray, source: np.ndarray, targets: np.ndarray, reach: float
          ) -> tuple[np.ndarray, np.ndarray]:
    """Rows of each ``source`` atom and each ``targets`` atom of another residue or group within ``reach`` Å of it."""
    if not len(source) or not len(targets):
        return np.empty(0, dtype=np.int64), np.empty(0, dtype=np.int64)
    near = cKDTree(coords[targets]).query_ball_point(coords[source], reach)
    first = np.repeat(source, [len(found) for found in near])
    second = targets[np.concatenate([np.asarray(found, dtype=np.int64) for found in near])]
    other = atoms.residue[first] != atoms.residue[second]
    return first[other], second[other]


def _pairs(first: np.ndarray, second: np.ndarray) -> np.ndarray:
    """(k, 2) each pair once, the lower row first, in increasing order (a pair may be found twice)."""
    pairs = np.sort(np.stack([first, second], axis=1), axis=1)
    return np.unique(pairs, axis=0) if len(pairs) else np.empty((0, 2), dtype=np.int64)
