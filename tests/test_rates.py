"""The numpy and numba method-of-lines rates agree; generic py-pde solvers work."""

import numpy as np
import pytest
from pde.backends import get_backend

import pdeflow

from .helpers import grid


def random_two_layer_state(n=64, seed=0):
    rng = np.random.default_rng(seed)
    g = grid(n)
    h1 = np.where(rng.random(n) < 0.2, 0.0, rng.uniform(0.01, 0.5, n))
    h2 = np.where(rng.random(n) < 0.2, 0.0, rng.uniform(0.01, 0.5, n))
    u1 = rng.normal(0, 1, n) * (h1 > 0)
    u2 = rng.normal(0, 0.5, n) * (h2 > 0)
    u2[::7] = 0.0  # some layers exactly at rest
    return g, dict(h1=h1, u1=u1, h2=h2, u2=u2)


@pytest.mark.parametrize("closure", ["paper", "relaxed"])
@pytest.mark.parametrize("bc", [("wall", "wall"), ("wall", "open"), ("open", "open")])
def test_two_layer_numba_and_numpy_rates_agree(bc, closure):
    g, prof = random_two_layer_state()
    eq = pdeflow.TwoLayerGranular(bc=bc, theta_deg=10, c=0.05, exchange_closure=closure,
                                  tau_star=0.3)
    st = eq.make_state(g, **prof)
    numpy_rate = eq.evolution_rate(st).data
    numba_rate = eq.make_evolution_rate(st, get_backend("numba"))(st.data, 0.0)
    assert np.abs(numpy_rate).max() > 1
    np.testing.assert_allclose(numba_rate, numpy_rate, rtol=1e-11, atol=1e-11)


def test_single_layer_numba_and_numpy_rates_agree():
    rng = np.random.default_rng(1)
    g = grid(50)
    h = np.where(rng.random(50) < 0.3, 0.0, rng.uniform(0.01, 1, 50))
    u = rng.normal(0, 1, 50) * (h > 0)
    u[::5] = 0.0
    eq = pdeflow.SingleLayerGranular(bc=("open", "wall"), theta_deg=20)
    st = eq.make_state(g, h=h, u=u)
    numpy_rate = eq.evolution_rate(st).data
    numba_rate = eq.make_evolution_rate(st, get_backend("numba"))(st.data, 0.0)
    np.testing.assert_allclose(numba_rate, numpy_rate, rtol=1e-11, atol=1e-11)


def test_generic_pyde_solver_runs_method_of_lines():
    g = grid(100, 0, 2)
    x = g.axes_coords[0]
    eq = pdeflow.TwoLayerGranular(bc=("wall", "open"), du_reg=0.1)
    st = eq.make_state(g, h1=np.where(x < 0.5, 0.1, 0.0), h2=np.where(x < 0.5, 0.1, 0.0))
    res = eq.solve(st, t_range=0.05, dt=2e-4, solver="runge-kutta", tracker=None,
                   backend="numba")
    assert np.all(np.isfinite(res.data))
    assert res.data[0][x > 0.5].sum() > 0  # the front moved
    r = eq.parameters.density_ratio
    assert np.sum(r * res.data[0] + res.data[2]) == pytest.approx(
        np.sum(r * st.data[0] + st.data[2]), rel=1e-6)


def test_fv_split_numpy_backend_matches_numba():
    g = grid(60, 0, 3)
    x = g.axes_coords[0]
    eq = pdeflow.TwoLayerGranular(bc=("wall", "open"))
    h2 = np.where(x < 1, np.minimum(1.0, (1 - x) * 1.7), 0.0)
    st = eq.make_state(g, h1=np.where(x < 1, 1.0 - h2, 0), h2=h2)
    # short run: thresholds (film deposition, bisection) amplify round-off later on
    a = eq.solve(st, t_range=0.05, solver="fv-split", backend="numba", tracker=None)
    b = eq.solve(st, t_range=0.05, solver="fv-split", backend="numpy", tracker=None)
    np.testing.assert_allclose(a.data, b.data, rtol=1e-9, atol=1e-9)


def test_method_of_lines_rate_honours_the_relaxed_closure():
    """A py-pde solver on the relaxed closure gets the relaxed rate, not the paper's:
    deposition bounded by r (h1 - h1_eq)/tau (at du = 0, h1_eq = 0), the same in the
    numpy and the numba rate."""
    g = grid(4)
    prof = dict(h1=np.full(4, 0.3), u1=np.zeros(4), h2=np.full(4, 0.5), u2=np.zeros(4))
    rates = {}
    for closure in ("paper", "relaxed"):
        eq = pdeflow.TwoLayerGranular(bc=("wall", "wall"), exchange_closure=closure,
                                      tau_star=0.5)
        st = eq.make_state(g, **prof)
        numpy_rate = eq.evolution_rate(st).data
        numba_rate = eq.make_evolution_rate(st, get_backend("numba"))(st.data, 0.0)
        np.testing.assert_allclose(numba_rate, numpy_rate, rtol=1e-12, atol=1e-12)
        rates[closure] = numpy_rate
    p = pdeflow.TwoLayerParameters()
    tau = 0.5 * np.sqrt(0.8 / p.g)
    # dh1/dt: the paper's closure at du = 0 is -(1 - k) g h1 tan(phi_int)/mol_eps
    assert rates["paper"][0, 1] < -100
    assert rates["relaxed"][0, 1] == pytest.approx(-0.3 / tau, rel=1e-12)


def test_method_of_lines_rate_bounds_erosion_by_the_relaxation():
    """Where the layers shear hard, the paper's closure erodes faster than the
    relaxation towards h1_eq allows: the relaxed rate is then the relaxation bound
    r (min(h1_eq, h1 + h2/r) - h1)/tau, in the numpy and the numba rate alike (an
    interior cell of a uniform state: no advection)."""
    g = grid(4)
    h1, h2, u1, c, tau_star = 0.05, 0.5, 3.0, 0.5, 3.0
    prof = dict(h1=np.full(4, h1), u1=np.full(4, u1), h2=np.full(4, h2), u2=np.zeros(4))
    rates = {}
    for closure in ("paper", "relaxed"):
        eq = pdeflow.TwoLayerGranular(bc=("wall", "wall"), exchange_closure=closure,
                                      tau_star=tau_star, c=c)
        st = eq.make_state(g, **prof)
        numpy_rate = eq.evolution_rate(st).data
        numba_rate = eq.make_evolution_rate(st, get_backend("numba"))(st.data, 0.0)
        np.testing.assert_allclose(numba_rate, numpy_rate, rtol=1e-12, atol=1e-12)
        rates[closure] = numpy_rate[0, 1]
    p = pdeflow.TwoLayerParameters()
    r, tan_int = p.density_ratio, np.tan(np.radians(p.phi_int_deg))
    paper = (c * u1**2 - (1 - p.k) * r * p.g * h1 * tan_int) / u1 / r
    h1_eq = c * u1**2 / ((1 - p.k) * r * p.g * tan_int)
    bound = (min(h1_eq, h1 + h2 / r) - h1) / (tau_star * np.sqrt((h1 + h2) / p.g))
    assert rates["paper"] == pytest.approx(paper, rel=1e-12)
    assert bound < paper
    assert rates["relaxed"] == pytest.approx(bound, rel=1e-12)
