"""What the atoms of a structure look like: colour schemes, bonds, ions and ligands (numpy/scipy).

Bonds are found by distance (covalent radii plus a tolerance, as molecular viewers do),
with a k-d tree; atoms of different alternate conformers are never bonded.
"""

from __future__ import annotations

from enum import StrEnum

import numpy as np
from scipy.spatial import cKDTree

from app.editor.scene.looks import RGB, SS_COLOURS
from core.protein.structure import Structure, ca_rows


class Colouring(StrEnum):
    """Colour schemes of the ribbon tube."""

    SECONDARY_STRUCTURE = "secondary structure"
    RESIDUE_TYPE = "residue type"
    CHAIN = "chain"
    RAINBOW = "rainbow, N to C"
    B_FACTOR = "B-factor"


SS_NAMES = {"H": "helix", "E": "sheet", "C": "other"}

RESIDUE_CLASSES: dict[str, tuple[RGB, tuple[str, ...]]] = {
    "hydrophobic": ((214, 190, 140), ("ALA", "VAL", "LEU", "ILE", "MET", "PHE", "TRP", "CYS", "MSE")),
    "polar": ((94, 186, 125), ("SER", "THR", "ASN", "GLN", "TYR")),
    "acidic": ((225, 70, 60), ("ASP", "GLU")),
    "basic": ((70, 120, 230), ("LYS", "ARG", "HIS")),
    "glycine, proline": ((190, 190, 190), ("GLY", "PRO")),
}
OTHER_RESIDUE: RGB = (200, 120, 200)

CHAIN_PALETTE: tuple[RGB, ...] = (
    (76, 114, 176), (221, 132, 82), (85, 168, 104), (196, 78, 82), (129, 114, 179),
    (147, 120, 96), (218, 139, 195), (140, 140, 140), (204, 185, 116), (100, 181, 205),
)  # fmt: skip

ELEMENT_COLOURS: dict[str, RGB] = {
    "C": (160, 160, 160), "N": (48, 80, 248), "O": (255, 13, 13), "S": (255, 200, 50),
    "P": (255, 128, 0), "H": (235, 235, 235), "SE": (255, 161, 0), "FE": (224, 102, 51),
    "ZN": (125, 128, 176), "MG": (138, 255, 0), "CA": (61, 255, 0), "NA": (171, 92, 242),
    "K": (143, 64, 212), "CL": (31, 240, 31), "MN": (156, 122, 199), "CU": (200, 128, 51),
    "CO": (240, 144, 160), "NI": (80, 208, 80), "CD": (255, 217, 143), "F": (144, 224, 80),
    "BR": (166, 41, 41), "I": (148, 0, 148),
}  # fmt: skip
OTHER_ELEMENT: RGB = (255, 20, 147)
LIGAND_CARBON: RGB = (80, 200, 120)

COVALENT_RADII: dict[str, float] = {
    "H": 0.31, "C": 0.76, "N": 0.71, "O": 0.66, "S": 1.05, "P": 1.07, "SE": 1.20, "F": 0.57,
    "CL": 1.02, "BR": 1.20, "I": 1.39, "B": 0.84, "SI": 1.11,
}  # fmt: skip
"""Å; elements not listed (metals) are not bonded: they are drawn as spheres."""
BOND_TOLERANCE = 0.45
"""Å added to the sum of the covalent radii."""


def residue_colours(structure: Structure, colouring: Colouring | str) -> np.ndarray:
    """Colour of every backbone residue (residue-table order), (n_residues, 3) uint8."""
    colouring = Colouring(colouring)
    segments = structure.segments
    if colouring is Colouring.SECONDARY_STRUCTURE:
        keys = np.concatenate([s.ss for s in segments])
        table = SS_COLOURS
        return np.array([table[k] for k in keys], dtype=np.uint8).reshape(-1, 3)
    if colouring is Colouring.RESIDUE_TYPE:
        by_name = {name: rgb for rgb, names in RESIDUE_CLASSES.values() for name in names}
        names = np.concatenate([s.resname for s in segments])
        return np.array([by_name.get(n, OTHER_RESIDUE) for n in names], dtype=np.uint8).reshape(-1, 3)
    if colouring is Colouring.RAINBOW:  # along each chain, as PyMOL's and ChimeraX's rainbow
        chain = np.concatenate([np.full(len(s), s.chain, dtype=object) for s in segments])
        along = np.zeros(len(chain))
        for name in dict.fromkeys(chain.tolist()):
            rows = np.flatnonzero(chain == name)
            along[rows] = np.arange(len(rows)) / max(len(rows) - 1, 1)
        return rainbow(along)
    if colouring is Colouring.B_FACTOR:  # each residue's Cα, blue (lowest) to white to red (highest)
        b = _calpha_b(structure)
        low, high = b.min(), b.max()
        return blue_white_red((b - low) / (high - low) if high > low else np.full(len(b), 0.5))
    order = {name: k for k, name in enumerate(dict.fromkeys(s.chain for s in segments))}
    colours = [CHAIN_PALETTE[order[s.chain] % len(CHAIN_PALETTE)] for s in segments for _ in range(len(s))]
    return np.array(colours, dtype=np.uint8).reshape(-1, 3)


def legend(structure: Structure, colouring: Colouring | str) -> list[tuple[str, RGB]]:
    """Labels and colours of a scheme, for the entries present in ``structure``."""
    colouring = Colouring(colouring)
    if colouring is Colouring.SECONDARY_STRUCTURE:
        return [(SS_NAMES[k], rgb) for k, rgb in SS_COLOURS.items()]
    if colouring is Colouring.RESIDUE_TYPE:
        return [(name, rgb) for name, (rgb, _) in RESIDUE_CLASSES.items()]
    if colouring is Colouring.RAINBOW:
        return [("N-terminus", _rgb(rainbow(np.zeros(1)))), ("C-terminus", _rgb(rainbow(np.ones(1))))]
    if colouring is Colouring.B_FACTOR:
        b = _calpha_b(structure)
        low, high = (float(b.min()), float(b.max())) if len(b) else (0.0, 0.0)
        if high <= low:
            return [(f"B {low:.0f} Å² (every Cα)", _rgb(blue_white_red(np.full(1, 0.5))))]
        return [(f"B {value:.0f} Å²", _rgb(blue_white_red(np.full(1, share))))
                for value, share in ((low, 0.0), ((low + high) / 2, 0.5), (high, 1.0))]
    chains = dict.fromkeys(s.chain for s in structure.segments)
    return [(f"chain {c}", CHAIN_PALETTE[k % len(CHAIN_PALETTE)]) for k, c in enumerate(chains)]


def rainbow(along: np.ndarray) -> np.ndarray:
    """(n, 3) uint8: blue at 0, through cyan, green and yellow, to red at 1 (hue 240° to 0°)."""
    hue = (1.0 - np.clip(along, 0.0, 1.0)) * 4.0  # in sixths of the circle: 0 red, 1 yellow, 2 green, 4 blue
    red = np.clip(2.0 - hue, 0.0, 1.0)
    green = np.minimum(np.clip(hue, 0.0, 1.0), np.clip(4.0 - hue, 0.0, 1.0))
    blue = np.clip(hue - 2.0, 0.0, 1.0)
    return np.round(np.stack([red, green, blue], axis=1) * 255).astype(np.uint8)


def blue_white_red(share: np.ndarray) -> np.ndarray:
    """(n, 3) uint8: blue at 0, white at 0.5, red at 1 (PyMOL's blue_white_red)."""
    share = np.clip(share, 0.0, 1.0)[:, None]
    blue, white, red = np.array([0.0, 0.0, 255.0]), np.array([255.0, 255.0, 255.0]), np.array([255.0, 0.0, 0.0])
    rgb = np.where(share < 0.5, blue + (white - blue) * share * 2.0, white + (red - white) * (share - 0.5) * 2.0)
    return np.round(rgb).astype(np.uint8)


def _rgb(colours: np.ndarray) -> RGB:
    """The first of ``colours`` (n, 3) as three ints."""
    red, green, blue = (int(c) for c in colours[0])
    return red, green, blue


def _calpha_b(structure: Structure) -> np.ndarray:
    """The B-factor (Å²) of each backbone residue's Cα."""
    return structure.atoms.b_factor[ca_rows(structure)]


def element_colours(elements: np.ndarray, carbon: RGB | None = None) -> np.ndarray:
    """CPK-like colours (n, 3) uint8 of element symbols; ``carbon`` overrides the colour of C."""
    table = dict(ELEMENT_COLOURS)
    if carbon is not None:
        table["C"] = carbon
    return np.array([table.get(e.upper(), OTHER_ELEMENT) for e in elements], dtype=np.uint8).reshape(-1, 3)


def bonds(coords: np.ndarray, elements: np.ndarray, altloc: np.ndarray, atoms: np.ndarray) -> np.ndarray:
    """Covalent bonds (b, 2) among the atom rows ``atoms``, by distance.

    Parameters
    ----------
    coords : (n_atoms, 3) positions, Å.
    elements, altloc : (n_atoms,) element symbols and alternate-location codes ('' if none).
    atoms : rows to consider; elements without a covalent radius are skipped.
    """
    radius = np.array([COVALENT_RADII.get(e.upper(), np.nan) for e in elements[atoms]])
    atoms = np.asarray(atoms)[np.isfinite(radius)]
    radius = radius[np.isfinite(radius)]
    if len(atoms) < 2:
        return np.empty((0, 2), dtype=np.int64)
    reach = 2 * max(COVALENT_RADII.values()) + BOND_TOLERANCE
    pairs = cKDTree(coords[atoms]).query_pairs(reach, output_type="ndarray")
    first, second = pairs[:, 0], pairs[:, 1]
    distance = np.linalg.norm(coords[atoms[first]] - coords[atoms[second]], axis=1)
    alt_first, alt_second = altloc[atoms[first]], altloc[atoms[second]]
    keep = (
        (distance <= radius[first] + radius[second] + BOND_TOLERANCE)
        & (distance > 0.4)
        & ((alt_first == "") | (alt_second == "") | (alt_first == alt_second))
    )
    return np.stack([atoms[first[keep]], atoms[second[keep]]], axis=1)


def ions_and_ligands(structure: Structure) -> tuple[np.ndarray, np.ndarray]:
    """Rows of ion atoms (a non-polymer, non-water group of one heavy atom) and of other ligand
    atoms (:attr:`~core.protein.structure.Structure.ligand_rows`)."""
    table = structure.atoms
    ligand = structure.ligand_rows
    heavy = ligand[np.char.upper(table.element[ligand].astype(str)) != "H"]
    groups, counts = np.unique(table.residue[heavy], return_counts=True)
    single = np.isin(table.residue[ligand], groups[counts == 1])
    return ligand[single & (np.char.upper(table.element[ligand].astype(str)) != "H")], ligand[~single]
