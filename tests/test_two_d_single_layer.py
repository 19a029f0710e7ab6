"""The single-layer model on a 2D CartesianGrid (issue 36, first step): its 2D kernels
(pdeflow/models/single_layer/two_d.py, sources_2d.py) and the py-pde shell on a 2D grid.

A state without cross-slope momentum (v = 0) gives the 1D arithmetic: the fluctuations
across a face add zero tangential momentum, and the vector friction step u* / |u*| s_new
is +-s_new exactly when v = 0 (sqrt(u*u) == |u| in IEEE arithmetic).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from pdeflow.models import SingleLayerParameters
from pdeflow.models.friction_laws import LAWS
from pdeflow.models.single_layer.kernels import kernels, kernels_2d
from pdeflow.numerics import layout as L

RNG = np.random.default_rng(36)
LAW_NAMES = ("coulomb", "pouliquen", "mu_i", "voellmy")


def _parameters(law: str, theta: float = 25.0) -> tuple[np.ndarray, object]:
    """(parameter vector, basal law's kernels or None) of a single layer with ``law``."""
    p = SingleLayerParameters(theta_deg=theta, phi_b_deg=20.0, friction_law=law)
    return p.to_array(), (None if law == "coulomb" else LAWS[law].kernels)


@pytest.mark.parametrize("law", LAW_NAMES)
def test_v_zero_sources_are_the_1d_arithmetic(law):
    """On 400 random cells (depths 0..1 m, some dry, speeds up to 3 m/s either way, some
    at rest) with v = 0, the 2D source stage, MUSCL predictor and method-of-lines rate
    write exactly the 1D kernels' numbers into (h, hu) and leave hv at 0; exact
    comparison, since the 2D arithmetic reduces to the 1D one when v = 0 (module
    docstring)."""
    P, basal = _parameters(law)
    one, two = kernels(basal), kernels_2d(basal)
    n = 400
    h = RNG.uniform(0, 1, n) * (RNG.uniform(0, 1, n) > 0.1)
    u = RNG.uniform(-3, 3, n) * (RNG.uniform(0, 1, n) > 0.2)
    q1 = np.stack([h, h * u])
    q2 = np.stack([h, h * u, np.zeros(n)])
    d1, d2 = np.zeros(L.N_DIAG + n), np.zeros(L.N_DIAG + n)
    one.source_stage(q1, 0.01, 0.01, P, d1)
    two.source_stage(q2, 0.01, 0.01, P, d2)
    assert np.array_equal(q2[:2], q1) and not np.any(q2[2])
    assert np.array_equal(d1, d2)
    q1 = np.stack([h, h * u])
    q2 = np.stack([h, h * u, np.zeros(n)])
    one.predictor(q1, 0.05, P, 0, n - 1)
    two.predictor(q2, 0.05, P, 0, n - 1)
    assert np.array_equal(q2[:2], q1) and not np.any(q2[2])
    r1, r2 = np.zeros((2, n)), np.zeros((3, n))
    one.mol_sources(np.stack([h, h * u]), r1, P)
    two.mol_sources(np.stack([h, h * u, np.zeros(n)]), r2, P)
    assert np.array_equal(r2[:2], r1) and not np.any(r2[2])


def test_vector_coulomb_friction_opposes_the_velocity():
    """Horizontal (theta = 0), Coulomb mu = tan 20 deg: a cell moving at speed s in a
    random direction keeps its direction and leaves the step at max(s - dt g mu, 0)
    (relative 1e-14: a few roundings of the direction and the product); below the
    threshold the cell stops exactly (set-valued)."""
    P, _ = _parameters("coulomb", theta=0.0)
    stage = kernels_2d(None).source_stage
    dt, n = 0.02, 200
    mu_dt = dt * P[L.G_Z] * math.tan(math.radians(20.0))
    s = RNG.uniform(0, 4 * mu_dt, n)
    a = RNG.uniform(0, 2 * math.pi, n)
    h = np.full(n, 0.5)
    q = np.stack([h, h * s * np.cos(a), h * s * np.sin(a)])
    stage(q, dt, dt, P, np.zeros(L.N_DIAG + n))
    speed = np.hypot(q[1], q[2]) / h
    expected = np.maximum(s - mu_dt, 0.0)
    assert np.allclose(speed, expected, rtol=1e-14, atol=0.0)
    moving = expected > 0
    assert np.allclose(np.arctan2(q[2], q[1])[moving] % (2 * math.pi), a[moving],
                       rtol=1e-13, atol=1e-13)
    assert not np.any(q[1:, ~moving])
    assert 40 < moving.sum() < 180  # both branches are exercised
