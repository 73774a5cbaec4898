"""Properties to colour a molecular surface by: electrostatic potential and B-factor.

(Curvature comes from the surface itself: :meth:`core.surfaces.molecular.SurfaceField.mean_curvature`.)

The potential is Coulomb's law with a distance-dependent dielectric ``ε = 4r`` (the usual
screening for surface colouring), from formal charges of the ionisable groups at pH 7:

    φ(x) = 332.06 / 4 · Σ_i q_i / max(|x - a_i|, 1 Å)²   kcal/(mol·e)
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from core.protein.structure import AtomTable

COULOMB = 332.0637
"""e²/(4πε₀) in kcal·Å/mol."""

_SIDE_CHAIN_CHARGES = {
    ("LYS", "NZ"): 1.0,
    ("ARG", "NE"): 1 / 3, ("ARG", "NH1"): 1 / 3, ("ARG", "NH2"): 1 / 3,
    ("ASP", "OD1"): -0.5, ("ASP", "OD2"): -0.5,
    ("GLU", "OE1"): -0.5, ("GLU", "OE2"): -0.5,
}  # fmt: skip
_PHOSPHATE_OXYGENS = ("OP1", "OP2", "O1P", "O2P")
_ION_CHARGES = {"NA": 1.0, "K": 1.0, "MG": 2.0, "CA": 2.0, "ZN": 2.0, "MN": 2.0, "CL": -1.0}


def atom_charges(atoms: AtomTable) -> np.ndarray:
    """(n_atoms,) formal charges in e at pH 7.

    Lys NZ +1; Arg NE/NH1/NH2 +1/3 each; His neutral; Asp/Glu −1/2 on each carboxylate
    oxygen; each protein chain's first residue N +1 and its last residue's O/OXT −1
    (shared); nucleotide phosphate OP1/OP2 −1/2 each; ions (Na, K, Mg, Ca, Zn, Mn, Cl)
    their formal charge.
    """
    key = list(zip(atoms.resname.tolist(), atoms.name.tolist(), strict=True))
    charges = np.array([_SIDE_CHAIN_CHARGES.get(k, 0.0) for k in key])
    protein = atoms.category == "protein"
    for chain in np.unique(atoms.chain[protein]):
        residues = atoms.residue[protein & (atoms.chain == chain)]
        first, last = residues.min(), residues.max()
        charges[(atoms.residue == first) & (atoms.name == "N")] += 1.0
        carboxyl = (atoms.residue == last) & np.isin(atoms.name, ("O", "OXT"))
        charges[carboxyl] -= 1.0 / max(int(carboxyl.sum()), 1)
    nucleic = atoms.category == "nucleic"
    charges[nucleic & np.isin(atoms.name, _PHOSPHATE_OXYGENS)] = -0.5
    for resname, charge in _ION_CHARGES.items():
        charges[(atoms.category == "ligand") & (atoms.resname == resname) & (atoms.name == resname)] = charge
    return charges


def electrostatic_potential(points: object, coords: object, charges: object) -> np.ndarray:
    """Screened Coulomb potential (kcal/(mol·e), ε = 4r) at ``points`` (..., 3) from point
    charges ``charges`` (n,) in e at ``coords`` (n, 3) Å; exact sum in chunks."""
    points = np.asarray(points, dtype=np.float64)
    charges = np.asarray(charges, dtype=np.float64)
    charged = charges != 0
    sources, q = np.asarray(coords, dtype=np.float64)[charged], charges[charged]
    flat = points.reshape(-1, 3)
    potential = np.zeros(len(flat))
    chunk = max(1, 4_000_000 // max(len(q), 1))
    for start in range(0, len(flat), chunk):
        d2 = ((flat[start : start + chunk, None, :] - sources[None, :, :]) ** 2).sum(axis=2)
        potential[start : start + chunk] = (q / np.maximum(d2, 1.0)).sum(axis=1)
    return (COULOMB / 4.0 * potential).reshape(points.shape[:-1])


def nearest_atom_values(points: object, coords: object, values: object) -> np.ndarray:
    """``values`` (n,) of the atom nearest to each of ``points`` (..., 3), e.g. B-factors."""
    points = np.asarray(points, dtype=np.float64)
    _, nearest = cKDTree(np.asarray(coords, dtype=np.float64)).query(points.reshape(-1, 3))
    return np.asarray(values, dtype=np.float64)[nearest].reshape(points.shape[:-1])
