"""The upper layer at a step of a lower layer at rest (pdeflow.models.two_layer.flux,
``upper_layer_at_uncovered_step``): where the step rises above the upper layer's surface,
the scheme's viscosity does not lift upper-layer material onto it."""

import numpy as np
import pytest

from pdeflow.models.two_layer.flux import fluctuations as fluctuations_two_layer
from pdeflow.models.two_layer.kernels import KERNELS as TWO_LAYER
from pdeflow.numerics import layout as L
from pdeflow.numerics.advection import rate_kernel
from pdeflow.numerics.compiled import ready

G = 9.81
R = 0.67
DRY = 1e-6


def _fluct(flux: int, left: tuple, right: tuple):
    """Face fluctuations of the two-layer system; states as (h1, u1, h2) with the lower
    layer at rest."""
    fluct = ready(fluctuations_two_layer(flux))
    (h1L, u1L, h2L), (h1R, u1R, h2R) = left, right
    return fluct((h1L, h1L * u1L, h2L, 0.0), (h1R, h1R * u1R, h2R, 0.0), G, R, DRY)


@pytest.mark.parametrize("flux", [L.FLUX_HLL, L.FLUX_RUSANOV, L.FLUX_IFCP])
@pytest.mark.parametrize("h1_top", [0.0, 0.02])
def test_layer_below_a_step_is_not_lifted_onto_it(flux, h1_top):
    """Left: upper layer 0.1 m deep on a deposit 0.2 m high, creeping towards a step
    0.5 m high (its surface, 0.3 m, is below the top). Nothing of it may cross onto the
    step: the mass flux through the face is <= 0 (the flux's own depth viscosity
    alpha0 Delta h1 used to send ~0.1 m^2/s up)."""
    left = (0.1, 0.01, 0.2)
    right = (h1_top, 0.0, 0.5)
    dm, dp, _ = _fluct(flux, left, right)
    mass_flux = left[0] * left[1] + dm[0]  # F = f(q_L) + D^-
    assert mass_flux <= 0.0
    h1L, u1L, h2L = left
    h1R, u1R, h2R = right
    assert dm[0] + dp[0] == pytest.approx(h1R * u1R - h1L * u1L, abs=1e-15)  # mass kept
    if h1_top == 0.0:
        # a bare step top receives neither upper-layer mass nor momentum
        assert (dp[0], dp[1]) == (0.0, 0.0)
    else:
        # the momentum jump is still the path-conservative one of (24)
        jump_mom = (h1R * u1R**2 - h1L * u1L**2
                    + G * 0.5 * (h1L + h1R) * (h1R + h2R - h1L - h2L))
        assert dm[1] + dp[1] == pytest.approx(jump_mom, rel=1e-12)
    # the lower layer at rest keeps its own-depth split and no mass fluctuation
    dE = h2R - h2L + R * (h1R - h1L)
    assert (dm[2], dp[2]) == (0.0, 0.0)
    assert dm[3] == pytest.approx(0.5 * G * h2L * dE)
    assert dp[3] == pytest.approx(0.5 * G * h2R * dE)


def test_a_step_the_upper_layer_covers_keeps_the_fluxs_fluctuations():
    """Where the upper layer covers the step on both sides the fluctuations are the flux's
    own: the same as over the same depths with the lower layer sliding at 1e-300 m/s
    (which is not at rest, so no branch for layers at rest applies)."""
    left = (0.4, 0.3, 0.2)
    right = (0.15, 0.25, 0.5)
    dm, dp, _ = _fluct(L.FLUX_HLL, left, right)
    fluct = ready(fluctuations_two_layer(L.FLUX_HLL))
    (h1L, u1L, h2L), (h1R, u1R, h2R) = left, right
    ref_m, ref_p, _ = fluct((h1L, h1L * u1L, h2L, 1e-300), (h1R, h1R * u1R, h2R, 1e-300),
                            G, R, DRY)
    assert dm[:2] == ref_m[:2] and dp[:2] == ref_p[:2]


def test_pool_in_a_hollow_puts_no_mass_on_the_steps_and_no_potential_energy_in():
    """A slowly moving pool of upper layer in a hollow of a deposit at rest whose rims
    rise above the pool's surface: the advection rate gives the rims no upper-layer
    mass, and the mass rates do not raise the potential energy (per rho2)
    int r g (h1 h2 + h1^2/2) dx, whose rate is sum r g H_i dh1_i/dt dx."""
    n, dx = 30, 0.05
    h2 = np.where((np.arange(n) < 10) | (np.arange(n) >= 20), 0.5, 0.2)
    h1 = np.where(h2 < 0.5, 0.1, 0.0)
    u1 = np.where(h1 > 0, 0.02, 0.0)
    q = np.array([h1, h1 * u1, h2, np.zeros(n)])
    rate = np.zeros_like(q)
    advect = ready(rate_kernel(TWO_LAYER, L.FLUX_HLL, 1, L.LIMITER_MINMOD,
                               L.GEOMETRY_PLANAR))
    advect(q, rate, np.zeros((2, *q.shape)), dx, np.zeros((L.N_METRIC, n + 1)), L.BC_WALL,
           L.BC_WALL, G, R, DRY)
    rims = h2 == 0.5
    assert np.all(rate[0][rims] <= 0.0)
    assert np.sum(R * G * (h1 + h2) * rate[0]) * dx <= 1e-12
