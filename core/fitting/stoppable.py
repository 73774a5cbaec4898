"""L-BFGS that a caller can stop between evaluations (a fit's Cancel)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy import optimize


class _Stopped(Exception):
    """Raised inside the optimiser to stop it."""


def minimize_until_cancelled(negative: Callable[[np.ndarray], tuple[float, np.ndarray]], start: np.ndarray,
                             cancelled: Callable[[], bool], **options: float) -> None:
    """Minimise ``negative`` (value and gradient) from ``start`` by L-BFGS-B (``options`` as
    scipy's) until it converges or ``cancelled()`` says so at an evaluation. Returns nothing:
    ``negative`` keeps the best point it saw."""

    def checked(x: np.ndarray) -> tuple[float, np.ndarray]:
        if cancelled():
            raise _Stopped
        return negative(x)

    try:
        optimize.minimize(checked, start, jac=True, method="L-BFGS-B", options=options)
    except _Stopped:
        pass
