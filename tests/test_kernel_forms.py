"""Kernels rewritten for speed give the results of their straightforward form, bit for bit.

The two-layer source stage's hot kernels were reordered so that independent chains of
divisions and square roots run side by side (docs/performance.md, *Two layers against
one*); the arithmetic of every result is unchanged. These tests hold the kernels to
plain Python versions of the straightforward form (the same IEEE operations in the same
order, so the results must be equal, not close).
"""

import math

import numpy as np
import pytest

from pdeflow.models.two_layer.exchange import friction_two_layer
from pdeflow.models.two_layer.hyperbolicity import (
    band_lower_edge,
    is_hyperbolic,
    lower_bound_fl,
    restoration_target,
)
from pdeflow.numerics import layout as L


def _sign(x):
    return 1.0 if x > 0.0 else (-1.0 if x < 0.0 else 0.0)


def _drag_root(y, mass, cdt):
    if y <= 0.0:
        return 0.0
    if cdt <= 0.0:
        return y / mass
    return 2.0 * y / (mass + math.sqrt(mass * mass + 4.0 * cdt * y))


def _friction_sequential(b1, b2, m1, m2, Kdt, Cdt, Bdt):
    """Stage (32) in its sequential form: stuck test first, then the sliding solution
    in the direction of the push."""
    u1 = _sign(b1) * _drag_root(m1 * abs(b1) - Kdt, m1, Cdt)
    push = m2 * b2 + m1 * (b1 - u1)
    if abs(push) <= Bdt:
        return u1, 0.0
    s2 = _sign(push)
    mt = m1 + m2
    p = m1 * b1 + m2 * b2 - Bdt * s2
    mu = m1 * m2 / mt
    rel = m1 * (b1 - p / mt)
    d = _sign(rel) * _drag_root(abs(rel) - Kdt, mu, Cdt)
    u2 = (p - m1 * d) / mt
    if u2 * s2 < 0.0:
        u2 = 0.0
    return u2 + d, u2


def test_friction_two_layer_is_the_sequential_form_bit_for_bit():
    rng = np.random.default_rng(11)
    n = 20000
    b = rng.uniform(-6, 6, (n, 2))
    m = rng.uniform(1e-4, 2.0, (n, 2))
    kcb = rng.uniform(0, 1, (n, 3)) * rng.uniform(0, 4, (n, 1))
    kcb[rng.random(n) < 0.1, 1] = 0.0  # no collisional drag
    kcb[rng.random(n) < 0.1, 2] = 0.0  # no basal friction
    b[rng.random(n) < 0.05, 1] = 0.0  # lower layer at rest before the step
    stuck = slid = 0
    for (b1, b2), (m1, m2), (k, c, bb) in zip(b, m, kcb, strict=True):
        args = (float(b1), float(b2), float(m1), float(m2), float(k), float(c), float(bb))
        got = friction_two_layer(*args)
        assert got == _friction_sequential(*args), args
        stuck += got[1] == 0.0
        slid += got[1] != 0.0
    assert stuck > 1000 and slid > 1000  # both branches exercised


@pytest.mark.parametrize("mode", [L.HYPERBOLICITY_EXACT, L.HYPERBOLICITY_BOUND])
def test_restoration_target_is_the_test_and_the_edge_bit_for_bit(mode):
    """One pass of the test and the edge search gives what the two separate kernels
    give: not is_hyperbolic, and band_lower_edge from |du| (F_L in bound mode)."""
    rng = np.random.default_rng(5)
    bad = 0
    for _ in range(4000):
        h1, h2 = rng.uniform(1e-4, 2.0, 2)
        r = rng.uniform(0.3, 0.99)
        du = rng.uniform(-2, 2) * math.sqrt(9.81 * (h1 + h2))
        got = restoration_target(h1, h2, du, 9.81, r, mode)
        hyperbolic = is_hyperbolic(h1, h2, du, 0.0, 9.81, r, mode)
        assert got[0] == (not hyperbolic)
        if got[0]:
            bad += 1
            edge = (lower_bound_fl(h1, h2, 9.81, r) if mode == L.HYPERBOLICITY_BOUND
                    else band_lower_edge(h1, h2, 9.81, r, abs(du)))
            assert got[1] == edge
    assert bad > 500
