"""The header every model's kernel parameter vector starts with (g_z, g_x), written once
(pdeflow.models.parameters) and used by every model's ``to_array``."""

from __future__ import annotations

import math

import pytest

from pdeflow import systems
from pdeflow.numerics import layout as L


@pytest.mark.parametrize("name", systems.names())
@pytest.mark.parametrize("theta", [-20.0, 0.0, 35.0])
def test_every_model_vector_starts_with_gravity_normal_to_and_along_the_bed(name, theta):
    """g cos(theta), g sin(theta) in slots G_Z, G_X for every registered model (rel
    1e-15: the same two products, computed once; no round-off allowed beyond one ulp)."""
    params = systems.get(name).parameters_class(g=9.7, theta_deg=theta)
    P = params.to_array()
    assert P[L.G_Z] == pytest.approx(9.7 * math.cos(math.radians(theta)), rel=1e-15)
    assert P[L.G_X] == pytest.approx(9.7 * math.sin(math.radians(theta)), rel=1e-15,
                                     abs=1e-300)
