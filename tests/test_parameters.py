"""The header every model's kernel parameter vector starts with (g_z, g_x, g_y), written once
(pdeflow.models.parameters) and used by every model's ``to_array``."""

from __future__ import annotations

import math

import numpy as np
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


@pytest.mark.parametrize("name", systems.names())
@pytest.mark.parametrize("azimuth", [-180.0, -90.0, 0.0, 30.0, 45.0, 90.0, 180.0, -135.0])
def test_gravity_along_the_bed_points_along_the_slope_azimuth(name, azimuth):
    """g sin(theta) (cos a, sin a) in slots G_X, G_Y (to 1e-15 of g sin(theta): one
    product more than the slope alone); on the axes exactly (+-g sin(theta), 0) or (0,
    +-g sin(theta)), so that a plane inclined along y has no gravity along x; azimuth
    0, the default, gives the vector of before the azimuth, to the bit."""
    params = systems.get(name).parameters_class
    P = params(g=9.7, theta_deg=35.0, slope_azimuth_deg=azimuth).to_array()
    along = 9.7 * math.sin(math.radians(35.0))
    a = math.radians(azimuth)
    assert P[L.G_X] == pytest.approx(along * math.cos(a), rel=0, abs=1e-15 * along)
    assert P[L.G_Y] == pytest.approx(along * math.sin(a), rel=0, abs=1e-15 * along)
    if azimuth % 90.0 == 0.0:
        assert sorted(np.abs(P[[L.G_X, L.G_Y]])) == [0.0, along]
    if azimuth == 0.0:
        assert P[L.G_Y] == 0.0 and P[L.G_X] == along
        assert np.array_equal(P, params(g=9.7, theta_deg=35.0).to_array())
