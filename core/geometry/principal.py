"""The principal directions of a cloud of points from its 3 × 3 scatter matrix, in plain Python
(the window's sketch of the molecule takes its view from them before numpy loads, and the 3D view
the same), each with one sign on every machine."""

from __future__ import annotations

import math
from collections.abc import Sequence

Vector = tuple[float, float, float]
SWEEPS = 50
"""Most Jacobi sweeps; a 3 × 3 matrix needs about five."""


def principal_directions(scatter: Sequence[Sequence[float]]) -> tuple[Vector, Vector, Vector]:
    """Unit eigenvectors of the symmetric 3 × 3 matrix ``scatter``, by increasing eigenvalue (for a
    cloud's scatter, from its direction of least extent to that of most), each signed so that its
    component of largest magnitude (the first of equal ones) is positive. Cyclic Jacobi rotations."""
    a = [[float(scatter[i][j]) for j in range(3)] for i in range(3)]
    v = [[float(i == j) for j in range(3)] for i in range(3)]  # columns: the eigenvectors
    for _ in range(SWEEPS):
        if a[0][1] ** 2 + a[0][2] ** 2 + a[1][2] ** 2 <= 1e-30 * sum(a[i][i] ** 2 for i in range(3)):
            break
        for p, q in ((0, 1), (0, 2), (1, 2)):
            if a[p][q] == 0.0:
                continue
            theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q])
            t = math.copysign(1.0, theta) / (abs(theta) + math.sqrt(theta * theta + 1.0))
            c = 1.0 / math.sqrt(t * t + 1.0)
            s = t * c
            for m in (a, v):  # columns p and q turned: m J
                for row in m:
                    row[p], row[q] = c * row[p] - s * row[q], s * row[p] + c * row[q]
            a[p], a[q] = ([c * x - s * y for x, y in zip(a[p], a[q])],  # rows p and q: Jᵀ (a J)
                          [s * x + c * y for x, y in zip(a[p], a[q])])
    order = sorted(range(3), key=lambda k: a[k][k])
    return tuple(_signed([v[i][k] for i in range(3)]) for k in order)  # type: ignore[return-value]


def _signed(vector: list[float]) -> Vector:
    """``vector`` made unit, its component of largest magnitude positive."""
    norm = math.sqrt(sum(x * x for x in vector))
    sign = math.copysign(1.0, max(vector, key=abs))
    return (sign * vector[0] / norm, sign * vector[1] / norm, sign * vector[2] / norm)
