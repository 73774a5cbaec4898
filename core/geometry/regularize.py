"""Regularization after a multiresolution edit: ideal peptide junctions, no new clashes.

Carson's edits move each residue as a rigid body with its curve and apply no other
constraint, so peptide bonds stretch and atoms run into each other. Here the residues an
edit moved (plus ``flank`` neighbours on each side) are moved again, each as a rigid body
whose carbonyl O may turn about the Cα–C bond (ψ), to the least-squares best compromise
(Levenberg–Marquardt, analytic Jacobian, sparse normal equations) of the terms below.
Where that leaves something validation would flag, a second fit from there also lets the
side chains that clash turn about their Cα–Cβ bond (χ1).

- **junctions** (σ = :data:`~core.geometry.restraints.JUNCTION_SIGMA`): each residue carries the ideal planar
  peptide that follows it, built from its own Cα, C and O with Engh & Huber values
  (C–N, Cα–C–N, C–N–Cα; ω = 180°, or 0° where the input peptide is cis); the next
  residue's N and Cα must sit on that peptide's N and Cα. This fixes the bond, both
  angles, ω and the carbonyl planarity and leaves φ and ψ free. Cα-only junctions keep
  their Cα–Cα distance.
- **the tether to the edited curve**: each residue's curve point C^r stays on the curve
  (σ = :data:`~core.geometry.restraints.TETHER_SIGMA` across it, :data:`~core.geometry.restraints.SLIDE_SIGMA` along it), and its Cα stays
  near where the edit put it (σ = :data:`~core.geometry.restraints.HOLD_SIGMA`).
- **torsions**: φ, ψ and χ1 stay near where the edit put them (σ = :data:`~core.geometry.restraints.TORSION_SIGMA`),
  and a φ or ψ that leaves its allowed Ramachandran region is pulled back to the nearest
  allowed point (σ = :data:`~core.geometry.restraints.RAMACHANDRAN_SIGMA`).
- **clashes** (σ = :data:`~core.geometry.restraints.CLASH_SIGMA`, one-sided and smooth): heavy-atom pairs (those
  :mod:`core.geometry.validation` checks, and turned atoms against the rest of their residue) are pushed
  apart until they overlap by at most :data:`~core.geometry.clash_list.CLASH_TARGET`, or by what they overlapped
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
Why loose to tight for a fit: a whole chain moved far has many ways to close its
junctions, and the one found tight at once depends on the last bits of the start; relaxed
first with the stiff terms soft and then tightened step by step (:data:`LOOSE_TO_TIGHT`),
it follows one path of minima to the same end from nearby starts.

:func:`regularized` turns an :class:`~core.protein.model.Edit` into the regularized edit (same
segment, same old state, so undo stays exact); :func:`regularize_region` regularizes any
stretch of residues of the current model; :func:`relax` is the array-level solver.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from core.geometry.least_squares import MAX_ITERATIONS, levenberg_marquardt
from core.geometry.restraints import CHI1, Restraints
from core.geometry.topology import topology
from core.protein.model import Edit, EditableModel
from core.protein.structure import Structure

FLANK = 3
"""Residues on each side of an edit that may move too (inside the segment)."""
TIGHT = (1.0,)
"""One relaxation with the stiff terms as they are: what an edit of a few residues needs."""
LOOSE_TO_TIGHT = tuple(60.0 / 1.25**k for k in range(19)) + (1.0,)
"""Relaxations with the stiff terms' σ this many times larger, each from where the last
ended: for a whole chain moved far (a fit), followed from loose to tight as a path of
minima. Relaxed tight at once, a fit's chain closes its junctions in whichever of many
minima its first steps fall into: adenylate kinase fitted open onto closed ended up to
0.46 Å apart from starts 0.001 Å apart and 1.29–1.39 Å from the target, with 2–5 new
Ramachandran outliers; through these twenty steps (each a few Levenberg–Marquardt steps),
the Cα held where the fit put them throughout, 0.04 Å apart and 0.83–0.84 Å from it, with
no new flag (four runs). Six steps from 30 left nine junctions open from some starts
(closed onto open), and undid the finest level."""


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


def regularized(model: EditableModel, edit: Edit, *, flank: int = FLANK, max_iterations: int = MAX_ITERATIONS,
                schedule: Sequence[float] = TIGHT) -> Edit:
    """The edit ``edit`` followed by regularization, as one :class:`Edit`.

    ``model`` may hold ``edit``'s old or new state (only ``edit.rows`` differ between the
    two). The result has the same segment, control points and old state; its residues and
    rows add up to ``flank`` neighbours on each side, so undo restores everything; atoms the
    edit moved outside them (the ligands it carried) keep its move.
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
    result = relax(model.structure, after, segment.residue_index[free], anchors, tangents, before,
                   max_iterations=max_iterations, schedule=schedule)
    rows = np.union1d(result.rows, edit.rows)  # (with the ligands the edit carried, as it moved them)
    new = after[rows]
    new[np.searchsorted(rows, result.rows)] = result.coords
    return Edit(edit.segment, edit.old_points, edit.new_points, free, rows, before[rows], new)


def regularize_region(
    model: EditableModel, segment: int, residues: object, *, flank: int = 0, reference: np.ndarray | None = None,
    max_iterations: int = MAX_ITERATIONS,
) -> Edit:
    """The edit that regularizes ``residues`` (indices within ``segment``) and up to
    ``flank`` neighbours on each side of the current model, tethered to its current curve
    (control points unchanged). Pairs may keep the overlap they had in ``reference``
    (default: the structure as read); ``max_iterations`` Levenberg–Marquardt steps at most."""
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
                   reference, max_iterations=max_iterations)
    return Edit(segment, ribbon.points, ribbon.points, free, result.rows, model.coords[result.rows], result.coords)


def relax(
    structure: Structure,
    coords: np.ndarray,
    residues: np.ndarray,
    anchors: np.ndarray,
    tangents: np.ndarray,
    reference: np.ndarray | None = None,
    *,
    max_iterations: int = MAX_ITERATIONS,
    schedule: Sequence[float] = TIGHT,
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
    max_iterations : Levenberg–Marquardt steps at most per fit.
    schedule : the softness of each relaxation in turn (:class:`~core.geometry.restraints.Restraints`),
        each from where the last ended, the Cα held where they were at the start, on the
        same curve: the stiff terms' σ times each, the last 1. One step (the default) suits
        an edit that moved a few residues; a whole chain moved far settles better loose
        first (:data:`LOOSE_TO_TIGHT`).

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
    start, iterations = coords.copy(), 0
    held = coords[topology(structure).backbone[residues, 1]]
    for softness in schedule:
        result = _relax_once(structure, start, residues, anchors, tangents, reference, max_iterations, softness, held)
        start[result.rows] = result.coords
        iterations += result.iterations
    return Relaxation(result.rows, result.coords, iterations, result.cost, result.settled)


def _relax_once(structure: Structure, coords: np.ndarray, residues: np.ndarray, anchors: np.ndarray,
                tangents: np.ndarray, reference: np.ndarray, max_iterations: int, softness: float,
                held: np.ndarray) -> Relaxation:
    """:func:`relax` at one ``softness``: the backbone first, then, where something would
    still be flagged, with the side chains that clash turning too."""
    backbone = _solve(Restraints(structure, coords, residues, anchors, tangents, reference, side_chains=False,
                                 softness=softness, held=held), max_iterations)
    if backbone.settled:
        return backbone
    # something would still be flagged: side chains that clash may turn too (χ1), from here
    start = coords.copy()
    start[backbone.rows] = backbone.coords
    problem = Restraints(structure, start, residues, anchors, tangents, reference, side_chains=True,
                         softness=softness, held=held)
    if not problem.axis[:, CHI1].any():  # no side chain clashes: nothing new to try
        return backbone
    result = _solve(problem, max_iterations)
    return Relaxation(result.rows, result.coords, backbone.iterations + result.iterations, result.cost, result.settled)


def _with_flanks(residues: np.ndarray, flank: int, n_residues: int) -> np.ndarray:
    """``residues`` and up to ``flank`` neighbours on each side, within ``0..n_residues-1``."""
    if flank < 0:
        raise ValueError(f"flank must be >= 0; got {flank}")
    spread = (np.asarray(residues, dtype=np.int64)[:, None] + np.arange(-flank, flank + 1)).ravel()
    return np.unique(spread[(spread >= 0) & (spread < n_residues)])


def _solve(problem: Restraints, max_iterations: int) -> Relaxation:
    """Levenberg–Marquardt on ``problem`` from the start positions."""
    fit = levenberg_marquardt(problem, max_iterations)
    coords = problem.atoms(fit.state)[problem.rows].copy()
    return Relaxation(problem.rows, coords, fit.iterations, fit.cost, not problem.violated(fit.residual))
