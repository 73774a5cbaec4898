"""Nucleic acids as they are drawn (numpy and scipy only): a tube through each strand's
phosphorus atoms, and each base as a flat slab of its ring joined to the backbone by a
stick, coloured by base (A red, G green, C yellow, T blue, U cyan, as the NDB colours them; a
modified base as its parent, grey where it has none).
No curve of the editor is defined on them: they are drawn, not edited."""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy.interpolate import make_interp_spline

from app.editor.scene import tube
from core.protein.structure import AtomTable, nucleotide_letter

SAMPLES = 6
"""Tube rings per nucleotide."""
RADIUS = 0.9
"""Å, the backbone tube."""
SIDES = 10
GAP = 9.0
"""Å: phosphorus atoms further apart than this are in two strands (a break in the chain)."""
PURINE = ("N9", "C8", "N7", "C5", "C6", "N1", "C2", "N3", "C4")
PYRIMIDINE = ("N1", "C2", "N3", "C4", "C5", "C6")
"""The outlines of the bases' rings, in order around them."""
BASE_COLOURS = {"A": (220, 70, 70), "G": (70, 170, 85), "C": (235, 195, 40), "T": (70, 100, 225),
                "U": (70, 190, 220)}
OTHER_BASE = (150, 150, 160)


@dataclass(frozen=True)
class Nucleotides:
    """The nucleotides of a model, strand by strand.

    Attributes
    ----------
    backbone : (n,) row of each nucleotide's phosphorus (its C4' where it has none).
    strand_start : (s + 1,) the first nucleotide of each strand, and n.
    outline : rows of every base's ring atoms, base after base (:data:`PURINE` or :data:`PYRIMIDINE`).
    outline_start : (n + 1,) where each base's outline begins in ``outline`` (empty where it has none).
    glycosidic : (n, 2) rows of C1' and of the base's N9 or N1, -1 where missing.
    colours : (n, 3) uint8, each base's colour.
    chain : (n,) str, each nucleotide's chain.
    """

    backbone: np.ndarray
    strand_start: np.ndarray
    outline: np.ndarray
    outline_start: np.ndarray
    glycosidic: np.ndarray
    colours: np.ndarray
    chain: np.ndarray

    def __len__(self) -> int:
        return len(self.backbone)


@lru_cache(maxsize=4)
def nucleotides(atoms: AtomTable) -> Nucleotides:
    """The nucleotides among ``atoms`` (category ``nucleic``) that have a phosphorus or a C4'
    (cached: the view and the sequence bar draw the same, and atom tables do not change)."""
    rows = np.flatnonzero(atoms.category == "nucleic")
    groups = np.split(rows, np.flatnonzero(np.diff(atoms.residue[rows])) + 1) if len(rows) else []
    backbone, outline, counts, glycosidic, colours, chain = [], [], [], [], [], []
    for group in groups:
        names = {str(name): int(row) for name, row in zip(atoms.name[group], group) if atoms.altloc[row] in ("", "A")}
        anchor = names.get("P", names.get("C4'"))
        if anchor is None:
            continue
        ring = [names[name] for name in (PURINE if "N9" in names else PYRIMIDINE) if name in names]
        ring = ring if len(ring) >= 5 else []
        backbone.append(anchor)
        outline.extend(ring)
        counts.append(len(ring))
        glycosidic.append((names.get("C1'", -1), names.get("N9", names.get("N1", -1))))
        letter = nucleotide_letter(str(atoms.resname[group[0]]), atoms.parents)
        colours.append(BASE_COLOURS.get(letter.upper(), OTHER_BASE))
        chain.append(atoms.chain[group[0]])
    backbone_rows = np.array(backbone, dtype=np.int64)
    chain_array = np.array(chain, dtype=str)
    far = np.linalg.norm(np.diff(atoms.coords[backbone_rows], axis=0), axis=1) > GAP if len(backbone) > 1 else []
    breaks = np.flatnonzero((chain_array[1:] != chain_array[:-1]) | np.asarray(far, dtype=bool)) + 1
    starts = np.concatenate([[0], breaks, [len(backbone)]] if backbone else [[0]]).astype(np.int64)
    return Nucleotides(backbone_rows, starts,
                       np.array(outline, dtype=np.int64), np.concatenate([[0], np.cumsum(counts)]).astype(np.int64),
                       np.array(glycosidic, dtype=np.int64).reshape(-1, 2),
                       np.array(colours, dtype=np.uint8).reshape(-1, 3), chain_array)


def strand_path(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Centres and unit tangents of a smooth curve through ``points`` (m, 3): an interpolating
    cubic spline (a line for two), :data:`SAMPLES` rings per nucleotide, ``(m - 1) * SAMPLES + 1``."""
    m = len(points)
    if m == 1:
        return points.copy(), np.tile([1.0, 0.0, 0.0], (1, 1))
    spline = make_interp_spline(np.arange(m), points, k=min(3, m - 1))
    u = np.linspace(0.0, m - 1, (m - 1) * SAMPLES + 1)
    derivative = spline.derivative()(u)
    return spline(u), derivative / np.maximum(np.linalg.norm(derivative, axis=1, keepdims=True), 1e-12)


def backbone_tube(coords: np.ndarray, found: Nucleotides) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The strands' tubes as one mesh: points, normals, quads (q, 4), and the nucleotide of each point."""
    points, normals, faces, owner, start = [], [], [], [], 0
    for first, last in zip(found.strand_start[:-1], found.strand_start[1:]):
        centres, tangents = strand_path(coords[found.backbone[first:last]])
        ring_points, ring_normals = tube.ring_vertices(centres, tangents, tube.transported_normals(tangents),
                                                       np.full(len(centres), RADIUS), SIDES)
        points.append(ring_points)
        normals.append(ring_normals)
        faces.append(tube.tube_faces(len(centres), SIDES, start))
        nucleotide = first + np.minimum((np.arange(len(centres)) + SAMPLES // 2) // SAMPLES, last - first - 1)
        owner.append(np.repeat(nucleotide, SIDES))
        start += len(ring_points)
    if not points:
        return np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 4), dtype=np.int64), np.zeros(0, dtype=np.int64)
    return np.vstack(points), np.vstack(normals), np.vstack(faces), np.concatenate(owner)


def base_slabs(coords: np.ndarray, found: Nucleotides) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each base as a flat polygon, a fan of triangles about its centre: points (its outline
    then its centre, base after base), triangles (t, 3) and the nucleotide of each point."""
    points, faces, owner, start = [], [], [], 0
    for k in range(len(found)):
        ring = found.outline[found.outline_start[k]:found.outline_start[k + 1]]
        if not len(ring):
            continue
        outline = coords[ring]
        points.append(np.vstack([outline, outline.mean(axis=0)]))
        n = len(ring)
        side = np.arange(n)
        faces.append(np.stack([side, (side + 1) % n, np.full(n, n)], axis=1) + start)
        owner.append(np.full(n + 1, k))
        start += n + 1
    if not points:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64), np.zeros(0, dtype=np.int64)
    return np.vstack(points), np.vstack(faces), np.concatenate(owner)
