"""Functions with known answers, to check the study pipeline end to end
(``function = "tests.studyfunctions:ishigami"`` in a study file, with the checkout on
``sys.path``). Test support, outside the package."""

from __future__ import annotations

import math
import time

ISHIGAMI_A, ISHIGAMI_B = 7.0, 0.1


def ishigami(x1: float, x2: float, x3: float, delay: float = 0.0) -> dict[str, float]:
    """Ishigami & Homma (1990): y = sin x1 + a sin^2 x2 + b x3^4 sin x1 on [-pi, pi]^3.

    ``delay`` [s] makes an evaluation cost that much wall time (tests of scheduling and
    of resuming an interrupted study)."""
    if delay:
        time.sleep(delay)
    y = (math.sin(x1) + ISHIGAMI_A * math.sin(x2) ** 2
         + ISHIGAMI_B * x3**4 * math.sin(x1))
    return {"y": y}


def ishigami_indices(a: float = ISHIGAMI_A, b: float = ISHIGAMI_B
                     ) -> dict[str, tuple[float, ...]]:
    """Analytical first (S1) and total (ST) indices of x1, x2, x3."""
    pi = math.pi
    v1 = 0.5 * (1 + b * pi**4 / 5) ** 2
    v2 = a**2 / 8
    v13 = b**2 * pi**8 * (1 / 18 - 1 / 50)
    v = v1 + v2 + v13
    return {"S1": (v1 / v, v2 / v, 0.0), "ST": ((v1 + v13) / v, v2 / v, v13 / v)}


def schaffer(x: float) -> dict[str, float]:
    """Schaffer's problem N.1: minimise f1 = x^2 and f2 = (x - 2)^2; the Pareto set is
    0 <= x <= 2."""
    return {"f1": x * x, "f2": (x - 2.0) ** 2}
