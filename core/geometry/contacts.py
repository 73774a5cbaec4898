"""Polar contacts: the nitrogen and oxygen atoms of two residues or groups close enough for a
hydrogen bond (2.5 to 3.5 Å between donor and acceptor), as PyMOL's *find polar contacts*
and ChimeraX's ``contacts`` show them around a binding site. By distance, less the pairs the
backbone rules out: two amide nitrogens (donors only), two carbonyl oxygens (acceptors
only), a proline's nitrogen (neither), and the nitrogens bound to a metal (neither: a haem's
four and its histidine's, whose lone pairs the iron holds); so of side chains and ligands,
whose hydrogens a crystal structure seldom gives, a pair of two acceptors may be listed too."""

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
    metals = np.flatnonzero(np.isin(element, [e for e in np.unique(element) if e and gemmi.Element(e).is_metal]))
    if len(metals) and len(polar):  # the nitrogens a metal holds
        bound = cKDTree(coords[metals]).query(coords[polar], distance_upper_bound=METAL_BOND)[0] <= METAL_BOND
        polar = polar[~(bound & (element[polar] == "N"))]
    source = np.intersect1d(polar, chosen)
    if not len(source) or not len(polar):
        return np.empty((0, 2), dtype=np.int64)
    near = cKDTree(coords[polar]).query_ball_point(coords[source], reach)
    counts = np.array([len(found) for found in near])
    first = np.repeat(source, counts)
    second = polar[np.concatenate([np.asarray(found, dtype=np.int64) for found in near])]
    backbone = np.where(atoms.category == "protein", atoms.name, "")
    kind = np.select([backbone == "N", np.isin(backbone, ("O", "OXT"))], ["donor", "acceptor"], "")
    keep = ((atoms.residue[first] != atoms.residue[second])
            & (np.linalg.norm(coords[first] - coords[second], axis=1) >= CLOSEST)
            & ((kind[first] == "") | (kind[first] != kind[second])))
    if not among:
        keep &= ~np.isin(second, chosen)
    pairs = np.sort(np.stack([first[keep], second[keep]], axis=1), axis=1)  # a chosen pair is found twice
    return np.unique(pairs, axis=0) if len(pairs) else np.empty((0, 2), dtype=np.int64)
