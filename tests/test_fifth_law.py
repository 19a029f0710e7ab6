"""The recipe "a friction law" of docs/architecture.md, followed once: a fifth, toy basal
law defined here only (its kernels, its constants, one registration line), run by the
compiled loop and through a case file, ``Run`` and its summary.

The toy law is linear rate strengthening, mu(h, s) = mu1 + k s (k [s/m]), with the
model's own tan(phi_b) as mu1. Its backward-Euler step has the closed form
s = (a - dt gw mu1) / (1 + dt gw k) (0 where a <= dt gw mu1), and a uniform layer on a
slope theta slides at the steady speed s* = (tan theta - mu1) / k, the fixed point of
that step.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import pdeflow
from pdeflow.cases import load_case
from pdeflow.models import friction_laws
from pdeflow.numerics import compile_parallel
from pdeflow.numerics.compiled import cached
from pdeflow.numerics.rheology import BasalLaw
from pdeflow.simulate import Run
from tests.helpers import grid, step

K = 0.2
"""the toy law's rate coefficient k [s/m]"""


@cached(inline="always")
def toy_static(law, h):
    return law[0]


@cached(inline="always")
def toy_mu(law, h, s):
    return law[0] + law[1] * s


@cached(inline="always")
def toy_slope(law, h, s):
    return law[1]


@cached(inline="always")
def toy_speed(a, h, gw, hm, dt, law):
    y = a - dt * gw * law[0]
    return y / (1.0 + dt * gw * law[1]) if y > 0.0 else 0.0


def toy_accel_np(law, h, gw, hm, s):
    return gw * (law[0] + law[1] * s)


TOY = friction_laws.FrictionLaw(
    BasalLaw("toy", toy_static, toy_mu, toy_slope, toy_speed, toy_accel_np),
    lambda p, g_z, g, tan_b: (tan_b, K))


@pytest.fixture
def toy_law():
    """The toy law registered as ``friction_law = "toy"`` for one test."""
    friction_laws.register("toy", TOY)
    yield TOY
    friction_laws.unregister("toy")


@pytest.mark.parametrize("theta", [35.0, 40.0])
def test_uniform_layer_slides_at_the_toy_law_steady_speed(toy_law, theta):
    """A uniform layer released at rest on an open incline (it stays uniform: no face
    sees a jump) accelerates to s* = (tan theta - tan phi_b)/k, the fixed point of the
    law's step, whatever dt: after 60 s (about 100 relaxation times 1/(g_z k)) only
    round-off is left, and 1e-9 relative leaves room for that of the velocity
    hu / h."""
    eq = pdeflow.SingleLayerGranular(bc=("open", "open"), friction_law="toy",
                                     theta_deg=theta, phi_b_deg=30.0)
    q, t, *_ = step(eq, eq.make_state(grid(8, 0.0, 1.0), h=np.full(8, 0.1)), 60.0)
    u = q[1] / q[0]
    exact = (math.tan(math.radians(theta)) - math.tan(math.radians(30.0))) / K
    assert np.ptp(u) == 0.0
    assert abs(u[0] - exact) / exact < 1e-9, (u[0], exact)


def test_the_toy_law_runs_through_a_case_with_its_own_kernels(toy_law):
    """``<model>.friction_law = "toy"`` in a case: both models run it through ``Run``,
    each with a bundle of its own whose stage calls the toy law's step (and no shipped
    law's); the toy law's friction, Coulomb's tan(phi_b) and more, brings the dam break
    to rest before t_end with a shorter run-out (measured at dx = 0.05 m: 2.5 m
    against 4.95 m of the single layer, 1.75 m against 2.5 m of the two layers)."""
    sets = ["grid.dx=0.05", "case.t_end=3.0"]
    for model in ("single_layer", "two_layer"):
        coulomb = Run(load_case("cases/paper_5_1_dam_break.toml", sets), model).execute()
        case = load_case("cases/paper_5_1_dam_break.toml",
                         [*sets, f"{model}.friction_law='toy'"])
        pde = case.make_pde(model)
        assert pde.kernels is pde.system.law_kernels(toy_law.kernels)
        found: dict = {}
        compile_parallel._call_tree(pde.kernels.sources, found)
        speeds = {law.kernels.speed for law in friction_laws.LAWS.values() if law.kernels}
        assert [k for k in found.values() if k in speeds] == [toy_speed]
        toy = Run(case, model).execute()
        assert toy.summary["t_final"] < 3.0, model
        assert toy.summary["runout"] < coulomb.summary["runout"], model
