"""Levenberg–Marquardt for sparse nonlinear least squares over rigid bodies.

The solver knows nothing of proteins: a :class:`Problem` gives residuals and their sparse
Jacobian at a state, turns a step of the unknowns into per-body parameters, bounds how far
one step may go, and says whether anything would still be flagged.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np
from scipy import sparse
from scipy.sparse.linalg import splu

DAMPING = 1e-2
"""Initial Levenberg–Marquardt damping, relative to the diagonal."""
STALL = 3e-3
"""Stop when nothing would be flagged, or anyway when a step is predicted to lower the
objective by less than this fraction."""
MAX_ITERATIONS = 25
"""Levenberg–Marquardt steps at most per fit, unless told otherwise (typically 4–14 are
taken; edits that have not settled by then are over-constrained, and more steps rarely
remove a flag)."""


class State(Protocol):
    """Where the bodies are."""

    def moved(self, step: np.ndarray) -> State:
        """The state after ``step`` (per-body parameters, as :meth:`Problem.per_body` gives)."""


class Problem(Protocol):
    """What :func:`levenberg_marquardt` needs of a least-squares problem."""

    def start(self) -> State:
        """The state to start from."""

    def evaluate(self, state: State) -> tuple[np.ndarray, object]:
        """Residuals at ``state``, and what :meth:`jacobian` needs to differentiate them."""

    def jacobian(self, terms: object) -> sparse.csr_matrix:
        """The Jacobian of the residuals with respect to the unknowns."""

    def per_body(self, step: np.ndarray) -> np.ndarray:
        """Per-body parameters of a step of the unknowns."""

    def reach(self, per_body: np.ndarray) -> float:
        """How many times the longest allowed step ``per_body`` is (> 1: it is scaled down)."""

    def violated(self, residual: np.ndarray) -> bool:
        """Whether anything would still be flagged at these residuals."""


@dataclass(frozen=True)
class Fit:
    """The result of :func:`levenberg_marquardt`: the final state, its residuals, the
    objective ½ Σ residual² and the steps tried."""

    state: State
    residual: np.ndarray
    cost: float
    iterations: int


def levenberg_marquardt(problem: Problem, max_iterations: int = MAX_ITERATIONS) -> Fit:
    """Minimize ½ Σ residual² of ``problem`` from its start state.

    Steps longer than the problem allows are scaled down (and never end the fit); a fit
    ends when nothing is flagged, when a step is predicted to gain less than
    :data:`STALL` of the objective, or after ``max_iterations`` steps.
    """
    state = problem.start()
    residual, terms = problem.evaluate(state)
    jacobian = problem.jacobian(terms)
    normal = NormalMatrix(jacobian)
    cost = 0.5 * residual @ residual
    damping, growth = DAMPING, 2.0
    iterations = 0
    for iterations in range(1, max_iterations + 1):
        step = -normal.solve(jacobian.T @ residual, damping)
        per_body = problem.per_body(step)
        reach = problem.reach(per_body)
        limited = reach > 1.0
        if limited:
            step /= reach
            per_body /= reach
        predicted = cost - 0.5 * np.sum((residual + jacobian @ step) ** 2)
        trial = state.moved(per_body)
        trial_residual, terms = problem.evaluate(trial)
        trial_cost = 0.5 * trial_residual @ trial_residual
        if trial_cost < cost:
            gain = (cost - trial_cost) / max(predicted, 1e-300)
            state, residual, cost = trial, trial_residual, trial_cost
            jacobian = problem.jacobian(terms)
            normal = NormalMatrix(jacobian)
            damping = max(damping * max(1 / 3, 1 - (2 * gain - 1) ** 3), 1e-7)
            growth = 2.0
            if not limited and (not problem.violated(residual) or predicted < STALL * cost):
                break
        else:  # the same normal matrix, damped more
            damping *= growth
            growth *= 2
    return Fit(state, residual, float(cost), iterations)


class NormalMatrix:
    """The normal matrix ``J^T J`` of a Jacobian, to solve ``(J^T J + λ D) δ = g`` for
    several dampings λ (D its diagonal).

    For residues in chain order, junctions couple neighbouring bodies and most clash
    pairs residues a few apart, so the matrix is sparse and nearly banded; SuperLU
    (a fill-reducing order, no pivoting: it is positive definite) factors it in O(m).
    """

    def __init__(self, jacobian: sparse.csr_matrix) -> None:
        self.matrix = (jacobian.T @ jacobian).tocsc()  # symmetric: its CSR arrays are its CSC arrays
        self.matrix.sum_duplicates()  # sorted indices (splu would sort the arrays in place)
        column = np.repeat(np.arange(self.matrix.shape[1]), np.diff(self.matrix.indptr))
        self.diagonal = np.flatnonzero(self.matrix.indices == column)  # every unknown has terms: all are there
        self.values = self.matrix.data.copy()

    def solve(self, gradient: np.ndarray, damping: float) -> np.ndarray:
        """``δ`` for the damping λ = ``damping``."""
        data = self.matrix.data
        data[:] = self.values
        data[self.diagonal] *= 1.0 + damping
        data[self.diagonal] += 1e-12 * data[self.diagonal].max()
        factor = splu(self.matrix, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True})
        return factor.solve(gradient)
