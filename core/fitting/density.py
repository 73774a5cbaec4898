"""Fit a model into a density map coarse to fine: the map–model correlation as objective.

The model's density is a sum of Gaussians, one per heavy atom, of width
``σ = R / (π √2)`` for a map of resolution ``R`` (as Chimera's ``molmap`` simulates maps),
computed on an orthogonal grid by spreading the atoms by cubic B-splines and blurring with
:func:`scipy.ndimage.gaussian_filter` (:mod:`core.fitting.map_target`). The map is
resampled once onto that grid, in a box around the model. The objective is their
correlation about the mean (CC), whose gradient with respect to every atom is the blurred
derivative field interpolated at the atom.

At each level the unknowns are the level's control points of every fitted segment, as in
:mod:`core.fitting.coarse_to_fine`; L-BFGS maximises the CC less the energy of an elastic
network of the Cα (which keeps the chain from molding itself into any density) and less a
hold on how far the level moves the atoms (:data:`LEVEL_HOLD`). While it
climbs, each residue moves with its curve point (its turn left out), so the
objective is smooth and its gradient exact; the edits then remap the residues exactly,
turning, where the climb ended. (Climbing the exact remap with that gradient left L-BFGS
stopped by failed line searches wherever the mismatch caught it: adenylate kinase fitted
from starts 0.001 Å apart ended 0.14–0.39 Å apart after level 6; climbed smooth, 0.03–0.04 Å,
in half the time.) Each level is fitted twice,
with two networks on the same springs: a harmonic one, which keeps the domains as they
were, and one whose springs give way past :data:`GIVE_WAY` Å (the energy grows only as the
logarithm of the stretch beyond it), as contacts between domains break when they part; the
level keeps the fit the map correlates with better.

Each level sees the map blurred to the size of its spans (:func:`level_resolution`: two Å
per residue between control points, at least 12 Å): a level cannot follow finer detail, and
that detail (helices, side chains) gives its few control points local optima they cannot
climb out of; blurred, the map's basin is as wide as the level's motion. Adenylate kinase
fitted open into closed, levels 0–6 into a 6 Å map as it is, stopped with the Cα 2.5 Å from
the target; each level into the map as it sees it, 1.4 Å. A map cut sharply in Fourier
space (as an X-ray map is) ripples around its dense parts; at 10 Å its ripples held the
LID domain 5 Å short, at 12 Å the Gaussian smooths them out (3.5 → 1.7 Å). Only the
refinement sees the map as it is.

Before the levels, where the fit's levels begin with :data:`~core.fitting.domains.DOMAINS`,
the chain's smaller dynamic domain is moved into the map as a rigid body
(:mod:`core.fitting.domains`): a domain that must turn 30–60° is beyond the levels, whose
few coarse control points bend a chain rather than turn its parts (maltodextrin-binding
protein, its C-terminal domain turned 60° into a 10 Å map: 2.26 Å from the target after the
levels alone, 1.28 Å with the domain moved first).

After the levels and the regularization (:func:`~core.fitting.settle.settle`), the fit is
refined (:func:`refine`): every residue moves into the map on its own as a rigid body, its
side chains turning (:mod:`core.fitting.real_space`), and is regularized, twice: the
regularization, which costs the correlation a little each time, costs less as the model
settles. At the finest level a control point still carries about three residues and
each residue keeps its rotamer; adenylate kinase into a 6 Å map, open into closed, ended
at CC 0.957 and 1.47 Å with the side chains turned and the finest level fitted again, and
at CC 0.984 and 0.75 Å refined residue by residue.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import replace
from functools import partial

import numpy as np
from scipy.spatial import cKDTree

from core.curves.splines import spline_space
from core.fitting.coarse_to_fine import LevelFit, pushed_to_finest
from core.fitting.domains import DOMAINS, fit_domain
from core.fitting.map_target import RESOLUTION, MapTarget, heavy_atoms, occupancies
from core.fitting.real_space import refine_real_space
from core.fitting.settle import FIT_ITERATIONS, FitResult, settle
from core.fitting.stoppable import minimize_until_cancelled
from core.geometry.regularize import regularize_region
from core.geometry.vectors import lengths, pair_gradient
from core.protein.model import Edit, EditableModel, per_segment
from core.protein.structure import ca_rows

ITERATIONS_PER_LEVEL = 60
STIFFNESS = 0.01
"""CC per Å² of mean squared change of the elastic network's spring lengths."""
ELASTIC_CUTOFF = 10.0
"""Å: Cα closer than this at the start are joined by springs."""
REFINE_CYCLES = 2
"""Rounds of :func:`refine`: each residue moved into the map, then regularized."""
REFINE_FIRST_BLUR = 1.5
"""The first round of :func:`refine` sees the map blurred to this many times its resolution,
the others as it is: at 6 Å a loop of adenylate kinase (residues 166-171) has two places in
the map as it is, and the first round put it in one or the other as the last bits of its
start fell (fits 0.40 Å apart, one 0.71 Å from the target, three 0.52); blurred, the
loop's basin is one, and the fits end 0.05 Å apart, 0.58 Å from it."""
REFINE_STIFFNESS = 0.01
"""CC per Å² of the Cα network's mean squared change in :func:`refine` (as the levels'
:data:`STIFFNESS`): a residue follows the map only as far as its neighbours let it, or a
homologue's residues follow another protein's density (1RX4 into 3NZD at 10 Å: 3.64 Å
without it, 2.96 with it; 0.1 costs adenylate kinase 0.015 of its CC at 6 Å)."""
LEVEL_HOLD = 1e-3
"""CC per Å² of the mean squared move of the fitted atoms at a level, from where it began: a
level moves the chain only as far as the map asks clearly. Climbed to the end (see
:func:`_fit_level`), the levels drew ubiquitin's partly occupied tail 2.5 Å out of its own
crystal's 2.5 Å map (Cα rmsd 0.52 Å); held, 1.5 Å at its last residue (0.21 Å), and
adenylate kinase in an x-ray-like 10 Å map ends 1.09-1.10 Å from its target (1.06-1.08
without) from starts 0.03 Å apart."""
REFINE_HOLD = 3e-3
"""CC per Å² of the mean squared move of the atoms in a round of :func:`refine`: a residue
moves only as far as the map asks clearly. Without it the climb drifts along directions the
map hardly sees (at 10 Å, a residue's place along its neighbours), and stops wherever its
path from the last bits of the start takes it: adenylate kinase in an x-ray-like 10 Å map
ended 0.12 Å apart from starts 0.03 Å apart; held, 0.03 Å apart (1.10 Å from the target,
1.06 without), and in half the time."""
GIVE_WAY = 6.0
"""Å: the change of length past which the springs of the yielding network give way."""
LEVELS_RESOLUTION = 12.0
"""Å: the levels are fitted into the map blurred to this resolution at least, where it is
finer (:meth:`MapTarget.blurred`, :func:`level_resolution`); the refinement fits into the
map as it is."""
RESOLUTION_PER_RESIDUE = 2.0
"""Å per residue of a span between a level's control points: the resolution that level
sees the map at (:func:`level_resolution`; coarser levels see it coarser); control points
spaced less than half the map's resolution apart sample it finer than it resolves
(:func:`resolved_levels`)."""


def atom_correlation(model: EditableModel, target: MapTarget) -> Callable[[np.ndarray], tuple[float, np.ndarray]]:
    """The CC of ``model``'s heavy atoms (each by its :func:`occupancies`) with ``target`` as a
    function of all its coordinates: the CC and its gradient (n_atoms, 3), zero for the other
    atoms."""
    rows = heavy_atoms(model)
    weights = occupancies(model, rows)

    def correlation(coords: np.ndarray) -> tuple[float, np.ndarray]:
        cc, gradient = target.gradient(coords[rows], weights)
        total = np.zeros_like(coords)
        total[rows] = gradient
        return cc, total
    return correlation


class ElasticNetwork:
    """Springs between Cα closer than ``cutoff`` (Å) at rest: the energy, the mean over the
    springs of the squared change ``s`` of their lengths (Å²), keeps the fit from molding a
    chain into any density. With ``give_way`` (Å) each spring's energy is
    ``g² log(1 + s²/g²)`` instead: the same for small changes, far less for large ones."""

    def __init__(self, ca: np.ndarray, cutoff: float = ELASTIC_CUTOFF, give_way: float | None = None) -> None:
        pairs = cKDTree(ca).query_pairs(cutoff, output_type="ndarray")
        self.i, self.j = pairs[:, 0], pairs[:, 1]
        self.rest = np.linalg.norm(ca[self.i] - ca[self.j], axis=1)
        self.give_way = give_way

    def gradient(self, ca: np.ndarray) -> tuple[float, np.ndarray]:
        """The energy and its gradient (n, 3) with respect to each Cα."""
        vector = ca[self.i] - ca[self.j]
        length = lengths(vector)
        stretch = length - self.rest
        n = max(len(stretch), 1)
        if self.give_way is None:
            energy, slope = stretch**2, 2.0 * stretch
        else:
            ratio = (stretch / self.give_way) ** 2
            energy, slope = self.give_way**2 * np.log1p(ratio), 2.0 * stretch / (1.0 + ratio)
        force = (slope / (n * np.maximum(length, 1e-9)))[:, None] * vector
        return float(np.sum(energy) / n), pair_gradient(self.i, self.j, force, len(ca))


def fit_map_levels(
    model: EditableModel,
    segments: Sequence[int],
    target: MapTarget,
    levels: Sequence[int],
    *,
    stiffness: float = STIFFNESS,
    hold: float = LEVEL_HOLD,
    cancelled: Callable[[], bool] = lambda: False,
) -> Iterator[LevelFit]:
    """Fit ``model``'s ``segments`` into ``target`` at each of ``levels`` in turn (coarse
    first), applying each level's edits to ``model`` and yielding them; a level's score is
    the CC after it. The objective is the CC less ``stiffness`` times the energy of an
    elastic network of the Cα as they are at the start (:class:`ElasticNetwork`), harmonic
    or giving way past :data:`GIVE_WAY` Å, whichever fits the level better, and less ``hold``
    times the mean squared move of the fitted atoms from where the level began. Each level
    fits into the map as it sees it (:func:`level_resolution`), and its score is the CC
    with that map; levels finer than the map resolves are left out (:func:`resolved_levels`)."""
    ca = ca_rows(model.structure)[np.concatenate([model.segments[s].residue_index for s in segments])]
    networks: list[ElasticNetwork] = []  # at rest as the levels begin (after the domains)
    rows = _segment_rows(model, segments)

    for level in resolved_levels(model, segments, levels, target.resolution):
        if cancelled():
            return
        if level == DOMAINS:
            rows = heavy_atoms(model)
            yield fit_domain(model, segments, target, rows, occupancies(model, rows), cancelled=cancelled)
            continue
        if not networks:
            networks += [ElasticNetwork(model.coords[ca]), ElasticNetwork(model.coords[ca], give_way=GIVE_WAY)]
        start = time.perf_counter()
        at = target.blurred(level_resolution(model, segments, level, target.resolution))
        correlation = atom_correlation(model, at)
        cc, planned = max((_fit_level(model, segments, level, _restrained(correlation, network, ca, stiffness, rows,
                                                                           model.coords[rows], hold), cancelled)
                           for network in networks), key=lambda fit: fit[0])
        if cancelled():
            return
        for edit in planned:
            model.apply(edit)
        n_points = sum(spline_space(min(level, model.ribbons[s].level)).n_points for s in segments)
        yield LevelFit(level, n_points, cc, time.perf_counter() - start, tuple(planned), at.resolution)


def resolved_levels(model: EditableModel, segments: Sequence[int], levels: Sequence[int], resolution: float
                    ) -> list[int]:
    """``levels`` less those whose control points sample a map of ``resolution`` Å finer than
    it resolves: spaced less than half the resolution apart (:data:`RESOLUTION_PER_RESIDUE`
    times the residues of a span, on average; two samples across the finest detail, as
    Nyquist's rule asks). The domain stage and the coarsest level asked for are kept. Such a
    level's control points are held by nothing but the elastic network and the hold: in a
    homologue's 10 Å map HPr's level 6 (1.4 residues a span) bent the backbone into the other
    protein's side chains, breaking 57 peptide junctions, which the regularization closed one
    of two ways as the last bits of the start fell (fits 0.36 Å apart; to level 5, 0.03 Å).
    The refinement moves each residue after the levels."""
    fitted = [level for level in levels if level != DOMAINS]
    coarsest = min(fitted, default=None)
    return [level for level in levels if level in (DOMAINS, coarsest)
            or RESOLUTION_PER_RESIDUE * _span(model, segments, level) >= resolution / 2.0]


def _span(model: EditableModel, segments: Sequence[int], level: int) -> float:
    """Residues between ``level``'s control points of ``segments``, on average."""
    return float(np.mean([len(model.segments[s].residue_index) / 2 ** min(level, model.ribbons[s].level)
                          for s in segments]))


def level_resolution(model: EditableModel, segments: Sequence[int], level: int, resolution: float) -> float:
    """Å, the resolution a map of ``resolution`` Å is blurred to for ``level``'s control
    points of ``segments``: :data:`RESOLUTION_PER_RESIDUE` times the residues of a span
    between them (on average), at least :data:`LEVELS_RESOLUTION` and the map's own, at most
    the coarsest a fit takes."""
    return float(np.clip(RESOLUTION_PER_RESIDUE * _span(model, segments, level), max(LEVELS_RESOLUTION, resolution),
                         RESOLUTION[1]))


def _fit_level(model: EditableModel, segments: Sequence[int], level: int,
               evaluate: Callable[[np.ndarray], tuple[float, float, np.ndarray]],
               cancelled: Callable[[], bool]) -> tuple[float, list[Edit]]:
    """Maximise the objective over the level-``level`` control points of ``segments`` (L-BFGS)
    with every residue carried by its curve point (the turn of its frame left out: the
    objective smooth and its gradient exact, so the climb converges to where it would from
    any nearby start), then plan the edits there, which remap the residues exactly. Returns
    the CC of the planned model and the edits (not applied)."""
    ribbons = [model.ribbons[s] for s in segments]
    pushes = [pushed_to_finest(min(level, r.level), r.level) for r in ribbons]
    designs = [(r.space.design_matrix(r.residue_u) @ push) for r, push in zip(ribbons, pushes)]
    sizes = [push.shape[1] * 3 for push in pushes]
    backbones = [model.segments[s] for s in segments]
    rows = _segment_rows(model, segments)
    per_atom = np.concatenate([bone.atom_stop - bone.atom_start for bone in backbones])
    best: dict = {"value": -np.inf, "x": np.zeros(sum(sizes))}

    def negative(x: np.ndarray) -> tuple[float, np.ndarray]:
        parts = np.split(x, np.cumsum(sizes)[:-1])
        shift = np.concatenate([design @ part.reshape(-1, 3) for design, part in zip(designs, parts)])
        coords = model.coords.copy()
        coords[rows] += np.repeat(shift, per_atom, axis=0)
        value, _, gradient = evaluate(coords)
        if value > best["value"]:
            best.update(value=value, x=x.copy())
        running = np.cumsum(np.vstack([np.zeros((1, 3)), gradient]), axis=0)
        return -value, -np.concatenate([(design.T @ (running[bone.atom_stop] - running[bone.atom_start])).ravel()
                                        for bone, design in zip(backbones, designs)])

    minimize_until_cancelled(negative, best["x"], cancelled, maxiter=ITERATIONS_PER_LEVEL, gtol=1e-9, ftol=1e-9)
    parts = np.split(best["x"], np.cumsum(sizes)[:-1])
    edits = [model.plan(s, r.points + push @ part.reshape(-1, 3))
             for s, r, push, part in zip(segments, ribbons, pushes, parts) if np.any(part)]
    coords = model.coords.copy()
    for edit in edits:
        coords[edit.rows] = edit.new_coords
    return evaluate(coords)[1], edits


def fit_map(
    model: EditableModel,
    segments: Sequence[int],
    target: MapTarget,
    levels: Sequence[int],
    *,
    regularize: bool = True,
    cancelled: Callable[[], bool] = lambda: False,
) -> FitResult:
    """Fit ``model``'s ``segments`` into ``target`` at ``levels`` (coarse first),
    :func:`~core.fitting.settle.settle` it, then :func:`refine` it; every edit kept is
    applied to ``model``. Each level's score is the CC with the map as that level sees it
    (:func:`level_resolution`)."""
    fits = list(fit_map_levels(model, segments, target, levels, cancelled=cancelled))
    result = settle(model, fits, regularize=regularize, cancelled=cancelled)
    if not result.levels:
        return result
    refined = refine(model, segments, target, regularize=regularize, cancelled=cancelled)
    return replace(result, refinement=refined)


def refine(
    model: EditableModel,
    segments: Sequence[int],
    target: MapTarget,
    *,
    cycles: int = REFINE_CYCLES,
    stiffness: float = REFINE_STIFFNESS,
    hold: float = REFINE_HOLD,
    regularize: bool = True,
    cancelled: Callable[[], bool] = lambda: False,
) -> list[Edit]:
    """After the levels: ``cycles`` times (the first into the map blurred,
    :data:`REFINE_FIRST_BLUR`), move every residue into the map on its own, its side chains
    turning (:func:`~core.fitting.real_space.refine_real_space`), the CC less
    ``stiffness`` times the energy of an elastic network of the Cα as they are now and
    ``hold`` times the mean squared move of the atoms in the round (:data:`REFINE_HOLD`), then
    regularize what moved (the junctions it held softly close; each cycle costs the
    correlation less as the model settles). Returns the edits, applied, one per segment."""
    ca = ca_rows(model.structure)[np.concatenate([model.segments[s].residue_index for s in segments])]
    network = ElasticNetwork(model.coords[ca])
    rows = _segment_rows(model, segments)

    done: list[Edit] = []
    for cycle in range(cycles):
        if cancelled():
            break
        blurred = cycle == 0 and cycles > 1  # (at most to the coarsest resolution a fit takes)
        correlation = atom_correlation(model, target.blurred(min(target.resolution * REFINE_FIRST_BLUR, RESOLUTION[1]))
                                       if blurred else target)
        evaluate = _restrained(correlation, network, ca, stiffness, rows, model.coords[rows], hold)
        moved = refine_real_space(model, segments, partial(_without_cc, evaluate), cancelled=cancelled)
        for edit in moved:
            model.apply(edit)
        done.extend(moved)
        if regularize:  # also after a cancel: no junction is left open
            for edit in moved:
                step = regularize_region(model, edit.segment, edit.residues, max_iterations=FIT_ITERATIONS)
                model.apply(step)
                done.append(step)
    return per_segment(done)


def _restrained(correlation: Callable[[np.ndarray], tuple[float, np.ndarray]], network: ElasticNetwork,
                ca: np.ndarray, stiffness: float, rows: np.ndarray, begun: np.ndarray, hold: float
                ) -> Callable[[np.ndarray], tuple[float, float, np.ndarray]]:
    """The objective of a fit at atoms ``coords``: the CC less ``stiffness`` times the energy of
    ``network`` (on the Cα ``ca``) and less ``hold`` times the mean squared move of the atoms
    ``rows`` from ``begun``; returns it, the CC and its gradient per atom."""

    def evaluate(coords: np.ndarray) -> tuple[float, float, np.ndarray]:
        cc, total = correlation(coords)
        energy, pull = network.gradient(coords[ca])
        total[ca] -= stiffness * pull
        moved = coords[rows] - begun
        total[rows] -= (2.0 * hold / len(rows)) * moved
        return cc - stiffness * energy - hold * float(np.sum(moved**2)) / len(rows), cc, total
    return evaluate


def _without_cc(evaluate: Callable[[np.ndarray], tuple[float, float, np.ndarray]], coords: np.ndarray
                ) -> tuple[float, np.ndarray]:
    """``evaluate``'s objective and gradient at ``coords``, as a score of the refinement."""
    value, _, gradient = evaluate(coords)
    return value, gradient


def _segment_rows(model: EditableModel, segments: Sequence[int]) -> np.ndarray:
    """The coordinate rows of the atoms of ``segments``' residues, residue by residue."""
    return np.concatenate([np.arange(a, b) for s in segments
                           for a, b in zip(model.segments[s].atom_start, model.segments[s].atom_stop)])
