"""The cartoon's rings (numpy only): a cross-section per ring of a segment's sampling
(:class:`~app.editor.scene.curves.SegmentPath`) by secondary structure, laid in the residue's
peptide plane.

Each section is a superellipse ``|x/a|^e + |y/b|^e = 1`` (``e`` 2: an ellipse; 4: a slab
with rounded edges), ``a`` across the ribbon and ``b`` through it: helices a flat ribbon,
strands a slab ending in an arrow on their last residue, loops a round tube. One number of
vertices for all, so a ring's shape can change in place. Sizes are PyMOL's (its
``cartoon_oval_length``, ``cartoon_rect_length`` and their widths), loops a little thicker.

The ribbon lies in the peptide planes, as Carson's ribbons and PyMOL's cartoon do: across
it runs each residue's guide, its carbonyl C→O (or, with Cα only, the normal of the plane of
its Cα and its neighbours'), signed once so that neighbours agree (a strand's carbonyls
alternate), interpolated between residues and made perpendicular to the curve. Where the
curve runs along the guide (a helix smoothed to a rod at a coarse level: its carbonyls lie
along its axis) the section turns round, with the ribbon's width as radius: a helix at
coarse levels is a cylinder, as in Carson's Fig. 5. At a coarse level the guides are
averaged over the residues a control point carries (:func:`smoothed`), as the curve is.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from app.editor.scene.curves import eased
from app.editor.scene.tube import cross


class Section(NamedTuple):
    """A cross-section: half-width ``a`` and half-thickness ``b`` (Å), exponent ``e``."""

    a: float
    b: float
    e: float


HELIX = Section(1.35, 0.3, 2.0)
STRAND = Section(1.4, 0.35, 4.0)
LOOP = Section(0.35, 0.35, 2.0)
CYLINDER = Section(2.3, 2.3, 2.0)
"""A helix drawn as a cylinder (an option, as in Carson's Fig. 5)."""
ARROW = 2.2
"""Å, the half-width of a strand's arrow where it begins."""
ROUND_BELOW = (0.35, 0.75)
"""Where the guide, made perpendicular to the curve, keeps less than the first of these of
its length the section is round; above the second, as its kind says; eased between."""
_KINDS = {"H": HELIX, "E": STRAND}


def sections(ss: np.ndarray, rings_per_residue: int, cylinders: bool = False) -> np.ndarray:
    """(n_rings, 3) ``a, b, e`` of every ring of a segment whose residues have secondary
    structure ``ss`` ('H', 'E', else loop): eased over a residue from one kind to the next,
    the arrow on each strand's last residue narrowing from :data:`ARROW` to a loop; with
    ``cylinders``, helices are :data:`CYLINDER` from end to end (flat ended)."""
    k = rings_per_residue
    n = len(ss)
    owner = np.minimum(np.arange(n * k + 1) // k, n - 1)
    kinds = {"E": STRAND} if cylinders else _KINDS
    by_residue = np.array([kinds.get(s, LOOP) for s in ss], dtype=float)
    shapes = eased(by_residue[owner], k)
    strand = np.asarray(ss) == "E"
    for last in np.flatnonzero(strand & ~np.append(strand[1:], False)):
        along = np.linspace(0.0, 1.0, k + 1)
        rows = slice(last * k, last * k + k + 1)
        shapes[rows, 0] = ARROW + (LOOP.a - ARROW) * along
        shapes[rows, 1], shapes[rows, 2] = STRAND.b, STRAND.e
    if cylinders:
        shapes[np.asarray(ss)[owner] == "H"] = CYLINDER
    return shapes


def helices(ss: np.ndarray, rings_per_residue: int) -> list[tuple[int, int]]:
    """The first and last ring of each helix of a segment (its residues' rings)."""
    helix = np.concatenate([[False], np.asarray(ss) == "H", [False]])
    starts, stops = np.flatnonzero(helix[1:] & ~helix[:-1]), np.flatnonzero(~helix[1:] & helix[:-1])
    last_ring = len(ss) * rings_per_residue
    return [(int(a) * rings_per_residue, min(int(b) * rings_per_residue - 1 + (b == len(ss)), last_ring))
            for a, b in zip(starts, stops)]


def on_axis(centres: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``centres`` (m, 3) of a helix's rings moved onto its axis (their best line), and the
    axis' unit direction, from the first towards the last."""
    middle = centres.mean(axis=0)
    direction = np.linalg.svd(centres - middle, full_matrices=False)[2][0]
    if direction @ (centres[-1] - centres[0]) < 0.0:
        direction = -direction
    return middle + np.outer((centres - middle) @ direction, direction), direction


def residue_guides(coords: np.ndarray, backbone: np.ndarray) -> np.ndarray:
    """(n, 3) unit guide of each residue of a segment, across the ribbon: C→O where the
    residue has both (``backbone`` (n, 4): rows of N, Cα, C, O, -1 where missing), else the
    normal of the plane of its Cα and its neighbours' (an end residue takes its neighbour's)."""
    ca = coords[backbone[:, 1]]
    guides = np.zeros_like(ca)
    if len(ca) >= 3:
        plane = cross(ca[1:-1] - ca[:-2], ca[2:] - ca[1:-1])
        guides[1:-1] = plane
        guides[0], guides[-1] = plane[0], plane[-1]
    carbonyl = (backbone[:, 2] >= 0) & (backbone[:, 3] >= 0)
    guides[carbonyl] = coords[backbone[carbonyl, 3]] - coords[backbone[carbonyl, 2]]
    length = np.linalg.norm(guides, axis=1, keepdims=True)
    return np.divide(guides, length, out=np.zeros_like(guides), where=length > 1e-9)


def agreeing_signs(guides: np.ndarray) -> np.ndarray:
    """(n,) ±1 that turn each guide to agree with the one before it (a positive dot product)."""
    turns = np.einsum("ij,ij->i", guides[1:], guides[:-1]) < 0.0
    return np.concatenate([[1.0], np.where(np.cumsum(turns) % 2, -1.0, 1.0)])


def smoothed(guides: np.ndarray, window: int) -> np.ndarray:
    """``guides`` (n, 3) averaged over ``window`` residues around each (fewer at the ends): the
    guides of a level whose control points carry ``window`` residues each."""
    if window <= 1:
        return guides
    half = window // 2
    windows = sliding_window_view(np.pad(guides, ((half, half), (0, 0))), 2 * half + 1, axis=0)
    index = np.arange(len(guides))
    count = np.minimum(index + half + 1, len(guides)) - np.maximum(index - half, 0)
    return windows.sum(axis=2) / count[:, None]  # each residue's own sum: the same bits from any slice


def ring_guides(guides: np.ndarray, rings_per_residue: int, rings: np.ndarray, first: int, n_residues: int
                ) -> np.ndarray:
    """(r, 3) guides at ring indices ``rings`` of a segment of ``n_residues``: each residue's
    at its centre, interpolated linearly between residues (not unit). ``guides`` are those of
    residues ``first``, ``first + 1``, ... (the same bits whatever slice they come from)."""
    position = np.clip(rings / rings_per_residue - 0.5, 0.0, n_residues - 1)
    whole = np.floor(position)
    t = (position - whole)[:, None]
    low = whole.astype(np.int64)
    high = np.minimum(low + 1, n_residues - 1)
    return (1.0 - t) * guides[low - first] + t * guides[high - first]


def section_vertices(centres: np.ndarray, tangents: np.ndarray, guides: np.ndarray, fallback: np.ndarray,
                     shapes: np.ndarray, n_sides: int) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and unit vertex normals (r * n_sides, 3) of sections ``shapes`` (r, 3) at
    ``centres`` on a curve with unit ``tangents``, across along ``guides`` made perpendicular
    to the curve (``fallback``, unit and perpendicular, where nothing is left of them), round
    where little is left (:data:`ROUND_BELOW`)."""
    across = guides - np.einsum("ij,ij->i", guides, tangents)[:, None] * tangents
    length = np.linalg.norm(across, axis=1)
    kept = length / np.maximum(np.linalg.norm(guides, axis=1), 1e-12)
    across = np.where((kept > 1e-6)[:, None], across / np.maximum(length, 1e-12)[:, None], fallback)
    through = cross(tangents, across)
    flat = np.clip((kept - ROUND_BELOW[0]) / (ROUND_BELOW[1] - ROUND_BELOW[0]), 0.0, 1.0)
    flat = flat * flat * (3.0 - 2.0 * flat)  # smoothstep
    a, e = shapes[:, 0], shapes[:, 2]
    b = a + (shapes[:, 1] - a) * flat
    angle = 2.0 * np.pi * np.arange(n_sides) / n_sides
    cosine, sine = np.cos(angle)[None, :], np.sin(angle)[None, :]
    power = 2.0 / e[:, None]
    x = a[:, None] * np.sign(cosine) * np.abs(cosine) ** power
    y = b[:, None] * np.sign(sine) * np.abs(sine) ** power
    nx = np.sign(cosine) * np.abs(cosine) ** (2.0 - power) / a[:, None]
    ny = np.sign(sine) * np.abs(sine) ** (2.0 - power) / b[:, None]
    points = centres[:, None, :] + x[..., None] * across[:, None, :] + y[..., None] * through[:, None, :]
    normals = nx[..., None] * across[:, None, :] + ny[..., None] * through[:, None, :]
    normals /= np.linalg.norm(normals, axis=2, keepdims=True)
    return points.reshape(-1, 3), normals.reshape(-1, 3)
