"""Speed of the curve engine: the O(n) filter bank against dense analysis matrices, and edits.

Prints a table; run with ``python benchmarks/bench_curve_engine.py``. Targets: a
10,000-residue chain (2**14 segments) fully decomposed in under 5 ms; one edit pushed from
any level to the finest in under 1 ms for 2,000 residues (2**11 segments).
"""

from __future__ import annotations

import numpy as np
from timing import best_ms

from core.curves.editing import move_control_point, tug_curve
from core.curves.filters import level_filters, refinement_matrix, wavelet_matrix
from core.curves.wavelets import decompose, reconstruct

DENSE_UP_TO = 12  # dense analysis matrices beyond 2**12 + 3 rows take minutes and gigabytes


def dense_analysis(level: int) -> list[np.ndarray]:
    """``[A^j; B^j] = [P^j | Q^j]^{-1}`` for every level, as dense matrices (the naive way)."""
    return [
        np.linalg.inv(np.hstack([refinement_matrix(j).toarray(), wavelet_matrix(j).toarray()]))
        for j in range(level, 0, -1)
    ]


def dense_decompose(points: np.ndarray, inverses: list[np.ndarray]) -> list[np.ndarray]:
    details = []
    for inverse in inverses:
        both = inverse @ points
        n_coarse = (len(points) - 3) // 2 + 3
        points, detail = both[:n_coarse], both[n_coarse:]
        details.append(detail)
    return [points, *details]


def main() -> None:
    rng = np.random.default_rng(0)
    print("Filter bank, 3-D control points (best of 10 runs, ms)")
    print(f"{'level':>5} {'points':>7} {'decompose':>10} {'reconstruct':>12} {'per point (us)':>15} {'dense decompose':>16}")
    for level in range(6, 17):
        points = rng.normal(size=(2**level + 3, 3))
        for j in range(1, level + 1):
            level_filters(j)  # build the cached filters outside the timing
        transform = decompose(points)
        t_dec = best_ms(lambda: decompose(points))
        t_rec = best_ms(lambda: reconstruct(transform))
        dense = "-"
        if level <= DENSE_UP_TO:
            inverses = dense_analysis(level)
            dense = f"{best_ms(lambda: dense_decompose(points, inverses), repeats=3):.2f}"
        print(f"{level:>5} {len(points):>7} {t_dec:>10.3f} {t_rec:>12.3f} {1e3 * t_dec / len(points):>15.3f} {dense:>16}")

    finest = 11  # 2,000 residues pad to 2**11 segments
    print(f"\nOne edit pushed to the finest level {finest} (2,051 control points), best of 200 runs, ms")
    print(f"{'level':>6} {'move point':>11} {'tug curve':>10}")
    for level in (0, 2, 4, 6, 8, 9.5, 10, 10.75, 11):
        t_move = best_ms(lambda: move_control_point(level, 2, np.array([1.0, 0.0, 0.0]), finest), 200)
        t_tug = best_ms(lambda: tug_curve(level, 0.37, np.array([1.0, 0.0, 0.0]), finest), 200)
        print(f"{level:>6} {t_move:>11.3f} {t_tug:>10.3f}")


if __name__ == "__main__":
    main()
