"""Synthesis filters ``P^j``, ``Q^j`` and Gram matrices ``I^j`` of cubic B-spline wavelets.

Semi-orthogonal, minimal-support wavelets after Finkelstein & Salesin (1994), as
specified in the multiresolution mathematics document (sections 2-4 and 11.2):

* ``P^j`` (``n_j x n_{j-1}``) refines level-(j-1) control points to level j (knot insertion);
* ``I^j = <Phi^j | Phi^j>`` is the L2 Gram matrix of the level-j basis on [0, 1];
* ``Q^j`` (``n_j x 2**(j-1)``) spans the orthogonal complement of ``V^{j-1}`` in ``V^j``:
  ``(P^j)^T I^j Q^j = 0``; each column is scaled so its largest-magnitude entry is +1.

Everything is sparse and built once per level (:func:`level_filters` is cached), together
with the banded factorisations used by the O(n) filter bank in :mod:`core.curves.wavelets`.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Callable

import numpy as np
from scipy import sparse
from scipy.sparse import linalg as sparse_linalg

from core import _validate
from core.curves.splines import spline_space

Solver = Callable[[np.ndarray], np.ndarray]

# Interior cubic spline wavelet of Chui and Wang, largest entry +1 (rows 2k-3 ... 2k+7).
INTERIOR_WAVELET = (
    np.array([-1, 124, -1677, 7904, -18482, 24264, -18482, 7904, -1677, 124, -1], dtype=np.float64)
    / 24264.0
)
# Interior refinement column (1/8)[1 4 6 4 1] (rows 2k-3 ... 2k+1 open, 2k ... 2k+4 closed).
INTERIOR_REFINEMENT = np.array([1, 4, 6, 4, 1], dtype=np.float64) / 8.0
# Boundary columns of P^j (j >= 3), times 16: (first row, values).
_BOUNDARY_REFINEMENT = ((0, (16, 8)), (1, (8, 12, 3)), (2, (4, 11, 8, 2)))
_SMALL_REFINEMENT = {
    1: np.array([[16, 0, 0, 0], [8, 8, 0, 0], [0, 8, 8, 0], [0, 0, 8, 8], [0, 0, 0, 16]]),
    2: np.array(
        [
            [16, 0, 0, 0, 0],
            [8, 8, 0, 0, 0],
            [0, 12, 4, 0, 0],
            [0, 3, 10, 3, 0],
            [0, 0, 4, 12, 0],
            [0, 0, 0, 8, 8],
            [0, 0, 0, 0, 16],
        ]
    ),
}
# Columns of the open Q^j found by the minimal-support search before the interior pattern.
_BOUNDARY_WAVELETS = 3


@dataclass(frozen=True)
class LevelFilters:
    """The two-scale relation between level ``level - 1`` and ``level``.

    Attributes
    ----------
    P, Q : synthesis filters, sparse ``(n_j, n_{j-1})`` and ``(n_j, 2**(j-1))``.
    PtI, QtI : ``P^T I^j`` and ``Q^T I^j``, the right-hand sides of the normal equations.
    solve_coarse : solves ``I^{j-1} x = b`` (banded LU, O(n)).
    solve_detail : solves ``Q^T I^j Q x = b``.
    """

    level: int
    closed: bool
    P: sparse.csr_array
    Q: sparse.csr_array
    PtI: sparse.csr_array
    QtI: sparse.csr_array
    solve_coarse: Solver
    solve_detail: Solver


def refinement_matrix(level: int, closed: bool = False) -> sparse.csr_array:
    """``P^j``: level-(j-1) control points to level j, sparse ``(n_j, n_{j-1})``."""
    _validate.integer_level("level", level, 1, 30)
    if closed:
        return _periodic_columns(level, INTERIOR_REFINEMENT)
    if level in _SMALL_REFINEMENT:
        return sparse.csr_array(_SMALL_REFINEMENT[level] / 16.0)
    n_fine, n_coarse = 2**level + 3, 2 ** (level - 1) + 3
    rows, cols, vals = [], [], []
    for col, (first, values) in enumerate(_BOUNDARY_REFINEMENT):
        span = np.arange(first, first + len(values))
        weights = np.array(values) / 16.0
        rows += [span, n_fine - 1 - span]
        cols += [np.full(len(span), col), np.full(len(span), n_coarse - 1 - col)]
        vals += [weights, weights]
    interior = np.arange(3, n_coarse - 3)
    rows.append((2 * interior[:, None] - 3 + np.arange(5)).ravel())
    cols.append(np.repeat(interior, 5))
    vals.append(np.tile(INTERIOR_REFINEMENT, len(interior)))
    return sparse.csr_array(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n_fine, n_coarse)
    )


def gram_matrix(level: int, closed: bool = False) -> sparse.csr_array:
    """``I^j``: L2 inner products of the level-j basis functions on [0, 1] (sparse, SPD).

    Computed exactly (the integrand is a degree-6 polynomial per segment) with a
    4-point Gauss-Legendre rule on every segment.
    """
    space = spline_space(level, closed)
    nodes, weights = np.polynomial.legendre.leggauss(4)
    h = 1.0 / space.n_segments
    starts = np.arange(space.n_segments) * h
    u = (starts[:, None] + (nodes + 1.0) * (h / 2.0)).ravel()
    w = np.tile(weights * (h / 2.0), space.n_segments)
    basis = space.design_matrix(u)
    return sparse.csr_array(basis.T @ (basis * w[:, None]))


def wavelet_matrix(level: int, closed: bool = False) -> sparse.csr_array:
    """``Q^j``: minimal-support semi-orthogonal wavelets, sparse ``(n_j, 2**(j-1))``."""
    _validate.integer_level("level", level, 1, 30)
    if closed:  # all columns are translates; wrapped copies overlap below level 4: rescale
        wavelets = _periodic_columns(level, INTERIOR_WAVELET)
        first = wavelets[:, [0]].toarray().ravel()
        return sparse.csr_array(wavelets / first[np.argmax(np.abs(first))])
    n_fine, n_wavelets = 2**level + 3, 2 ** (level - 1)
    orthogonality = sparse.csc_array(refinement_matrix(level).T @ gram_matrix(level))
    left = (n_wavelets + 1) // 2  # columns built here; the others are their mirror images
    boundary: list[np.ndarray] = []
    for _ in range(min(left, _BOUNDARY_WAVELETS)):
        previous_start = int(np.flatnonzero(boundary[-1])[0]) if boundary else -1
        boundary.append(_minimal_support_wavelet(orthogonality, previous_start + 1, boundary))
    rows = [np.flatnonzero(column) for column in boundary]
    vals = [column[r] for column, r in zip(boundary, rows)]
    cols = [np.full(len(r), k) for k, r in enumerate(rows)]
    interior = np.arange(len(boundary), left)
    rows.append((2 * interior[:, None] - 3 + np.arange(len(INTERIOR_WAVELET))).ravel())
    cols.append(np.repeat(interior, len(INTERIOR_WAVELET)))
    vals.append(np.tile(INTERIOR_WAVELET, len(interior)))
    rows, cols, vals = np.concatenate(rows), np.concatenate(cols), np.concatenate(vals)
    mirrored = cols < n_wavelets - left
    rows = np.concatenate([rows, n_fine - 1 - rows[mirrored]])
    cols = np.concatenate([cols, n_wavelets - 1 - cols[mirrored]])
    vals = np.concatenate([vals, vals[mirrored]])
    return sparse.csr_array((vals, (rows, cols)), shape=(n_fine, n_wavelets))


def _minimal_support_wavelet(
    orthogonality: sparse.csc_array, first_start: int, previous: list[np.ndarray]
) -> np.ndarray:
    """Null vector of ``P^T I`` with the earliest start row and then the shortest support."""
    n_fine = orthogonality.shape[1]
    for start in range(first_start, n_fine):
        for length in range(1, min(n_fine - start, 12) + 1):
            block = sparse.coo_array(orthogonality[:, start : start + length])
            touched = np.unique(block.row)  # only the rows of P^T I that reach the window
            window = np.zeros((len(touched), length))
            window[np.searchsorted(touched, block.row), block.col] = block.data
            _, singular, vh = np.linalg.svd(window)
            rank = int(np.sum(singular > 1e-10 * singular.max(initial=0.0)))
            null = vh[rank:]
            if len(null) == 0 or np.abs(null[:, 0]).max() < 1e-9:
                continue
            vector = np.zeros(n_fine)
            vector[start : start + length] = null.T @ null[:, 0]
            if previous and np.linalg.matrix_rank(np.column_stack([*previous, vector])) <= len(previous):
                continue
            return vector / vector[np.argmax(np.abs(vector))]
    raise ArithmeticError("no minimal-support wavelet found")  # unreachable for cubic B-splines


def _periodic_columns(level: int, stencil: np.ndarray) -> sparse.csr_array:
    """Closed-curve filter: column k holds ``stencil`` from row 2k, wrapped modulo ``2**level``."""
    n_fine, n_coarse = 2**level, 2 ** (level - 1)
    cols = np.repeat(np.arange(n_coarse), len(stencil))
    rows = (2 * cols + np.tile(np.arange(len(stencil)), n_coarse)) % n_fine
    matrix = sparse.coo_array((np.tile(stencil, n_coarse), (rows, cols)), shape=(n_fine, n_coarse))
    return sparse.csr_array(matrix)  # duplicate (wrapped) entries are summed


def _spd_solver(matrix: sparse.csr_array) -> Solver:
    """Factorise a symmetric positive-definite sparse matrix once; return its solve function.

    The matrices are banded (cyclic-banded for closed curves): SuperLU in the natural
    order without pivoting is a banded LU with fill only inside the band (and the
    wrapped corner), so each solve is O(n). It beats LAPACK's banded Cholesky solve
    (``pbtrs``) by 1.5-2x here, because that one calls a BLAS kernel per row.
    """
    factor = sparse_linalg.splu(
        sparse.csc_array(matrix), permc_spec="NATURAL", diag_pivot_thresh=0.0, options={"SymmetricMode": True}
    )
    return factor.solve


@lru_cache(maxsize=None)
def level_filters(level: int, closed: bool = False) -> LevelFilters:
    """All filters and factorisations between level ``level - 1`` and ``level`` (cached)."""
    P = refinement_matrix(level, closed)
    Q = wavelet_matrix(level, closed)
    gram = gram_matrix(level, closed)
    PtI = sparse.csr_array(P.T @ gram)
    QtI = sparse.csr_array(Q.T @ gram)
    return LevelFilters(
        level=level,
        closed=closed,
        P=P,
        Q=Q,
        PtI=PtI,
        QtI=QtI,
        solve_coarse=_spd_solver(gram_matrix(level - 1, closed)),
        solve_detail=_spd_solver(sparse.csr_array(QtI @ Q)),
    )
