"""Basal friction laws (issue 23): exact steady flow rules, exact rest, h_stop deposits,
the backward-Euler step of each law, thin films, the method-of-lines twins."""

from __future__ import annotations

import math

import numpy as np
import pytest
from pde.backends import get_backend

import pdeflow
from pdeflow.models.friction_laws import LAWS as FRICTION_LAWS
from pdeflow.models.friction_laws import h_stop
from pdeflow.models.single_layer import layout as S
from pdeflow.models.two_layer import layout as T
from pdeflow.models.two_layer.laws import friction_two_layer_law
from pdeflow.numerics import layout as L
from pdeflow.numerics.rheology import basal_accel, law_block
from tests.helpers import grid, step

LAWS = ["pouliquen", "mu_i", "voellmy"]


def flow_rule(law: str, p, theta_deg: float, h: float) -> float:
    """The law's steady uniform speed [m/s] on a slope theta of a layer of depth h [m]."""
    th = math.radians(theta_deg)
    t, t1 = math.tan(th), math.tan(math.radians(p.delta1_deg))
    t2 = math.tan(math.radians(p.delta2_deg))
    if law == "pouliquen":  # u = beta sqrt(g h cos theta) h / h_stop(theta)
        return p.pouliquen_beta * math.sqrt(p.g * h * math.cos(th)) * h / h_stop(
            theta_deg, p)
    if law == "voellmy":  # u = sqrt(xi h (sin theta - mu cos theta))
        return math.sqrt(p.voellmy_xi * h * (math.sin(th) - p.voellmy_mu * math.cos(th)))
    # mu(I) = tan theta with I = 5 u d / (2 h sqrt(phi g h cos theta))
    i = p.mu_i_I0 * (t - t1) / (t2 - t)
    return 0.4 * i * h * math.sqrt(p.packing_fraction * p.g * math.cos(th) * h) \
        / p.grain_diameter


UNIFORM = [("pouliquen", 23.0, 5e-3), ("pouliquen", 25.0, 3e-3), ("pouliquen", 28.0, 2e-3),
           ("mu_i", 22.0, 4e-3), ("mu_i", 26.0, 2e-3),
           ("voellmy", 25.0, 0.5), ("voellmy", 35.0, 2.0)]


@pytest.mark.parametrize("law, theta, h", UNIFORM)
def test_uniform_layer_converges_to_the_law_flow_rule(law, theta, h):
    """A uniform layer released at rest on an open 8-cell incline (it stays uniform: no
    face sees a jump) accelerates to the law's steady speed; error < 0.1 % after 300 s."""
    eq = pdeflow.SingleLayerGranular(bc=("open", "open"), friction_law=law,
                                     theta_deg=theta)
    g = grid(8, 0.0, 1.0)
    q, t, *_ = step(eq, eq.make_state(g, h=np.full(8, h)), 300.0)
    if law == "pouliquen":
        assert h_stop(theta, eq.parameters) < h  # on the flowing branch Fr >= beta
    u = q[1] / q[0]
    exact = flow_rule(law, eq.parameters, theta, h)
    assert np.ptp(u) == 0.0
    assert abs(u[0] - exact) / exact < 1e-3


@pytest.mark.parametrize("law, theta, h1, h2", [("pouliquen", 25.0, 1e-3, 3e-3),
                                                ("pouliquen", 27.0, 2e-3, 2e-3),
                                                ("mu_i", 25.0, 1e-3, 2e-3)])
def test_two_layer_lower_layer_converges_to_the_flow_rule_of_the_total_depth(
        law, theta, h1, h2):
    """Two layers without exchange: the bed law sees H = h1 + h2, so the lower layer's
    steady speed is the flow rule of H (the upper layer slides on it by (22))."""
    eq = pdeflow.TwoLayerGranular(bc=("open", "open"), friction_law=law, theta_deg=theta,
                                  exchange_closure="none", hyperbolicity="none")
    q, *_ = step(eq, eq.make_state(grid(8, 0.0, 1.0), h1=np.full(8, h1),
                                   h2=np.full(8, h2)), 200.0)
    u2 = q[3] / q[2]
    exact = flow_rule(law, eq.parameters, theta, h1 + h2)
    assert abs(u2[0] - exact) / exact < 1e-3
    assert np.all(q[1] / q[0] > u2)


@pytest.mark.parametrize("two_layer, reconstruction", [(False, "first-order"),
                                                       (True, "first-order"),
                                                       (False, "muscl"), (True, "muscl")])
def test_layer_thinner_than_h_stop_stays_at_rest_for_100_s(two_layer, reconstruction):
    """A layer thinning from 0.9 to 0.3 h_stop(25 deg) down-slope (its surface slope
    ~1.6e-3 adds to the drive) stays at rest bit for bit for 100 s (with MUSCL too:
    the law's friction predictor holds the intermediate stage)."""
    theta = 25.0
    n = 50
    x = grid(n, 0.0, 0.5).axes_coords[0]
    if two_layer:
        # no exchange: the paper's closure deposits an upper layer at rest (du = 0),
        # which moves mass between the layers but is no motion (test_sources); k = 0.99
        # so that the interface (k tan 30 deg > tan 25 deg) holds the upper layer too
        eq = pdeflow.TwoLayerGranular(bc=("wall", "open"), friction_law="pouliquen",
                                      theta_deg=theta, exchange_closure="none", k=0.99,
                                      reconstruction=reconstruction)
    else:
        eq = pdeflow.SingleLayerGranular(bc=("wall", "open"), friction_law="pouliquen",
                                         theta_deg=theta, reconstruction=reconstruction)
    hs = h_stop(theta, eq.parameters)
    h = hs * (0.9 - 0.6 * x / 0.5)  # thinning down-slope
    assert np.abs(np.diff(h)).max() / 0.01 < 2e-3
    profiles = {"h1": 0.3 * h, "h2": 0.7 * h} if two_layer else {"h": h}
    state = eq.make_state(grid(n, 0.0, 0.5), **profiles)
    q0 = state.data.copy()
    q, t, steps, _, _ = step(eq, state, 100.0)
    assert t == pytest.approx(100.0) and steps > 100
    assert np.abs(q - q0).max() == 0.0


@pytest.mark.parametrize("theta", [23.0, 25.0, 28.0])
def test_draining_layer_stops_leaving_h_stop(theta):
    """A uniform layer of 3 h_stop released on an incline (wall up-slope, open down-slope,
    dx = 5 mm) drains and stops in finite time, leaving a deposit of h_stop(theta) over
    the middle of the slope: a little thinner, never thicker (a cell stops once friction
    mu_stop(h) > tan(theta) has braked it, and it keeps draining while braking; measured
    0.986-1.000 h_stop at 23 deg, 0.998-1.000 at 25, 0.970 at 28)."""
    n = 200
    eq = pdeflow.SingleLayerGranular(bc=("wall", "open"), friction_law="pouliquen",
                                     theta_deg=theta)
    hs = h_stop(theta, eq.parameters)
    q, t, steps, status, _ = step(eq, eq.make_state(grid(n, 0.0, 1.0), h=np.full(n, 3 * hs)),
                                  100.0, stop_at_rest=True)
    assert t < 50.0 and np.all(q[1] == 0.0)
    middle = q[0, n // 4: 3 * n // 4] / hs
    assert 0.95 < middle.min() and middle.max() < 1.0, (middle.min(), middle.max())


def law_parameters(law: str, model=pdeflow.SingleLayerGranular) -> np.ndarray:
    return model(friction_law=law, theta_deg=20.0).parameter_array()


@pytest.mark.parametrize("law", LAWS)
def test_backward_euler_step_is_the_root_and_set_valued(law):
    """u = 0 exactly when |b| <= dt g_z mu_static(h); otherwise u solves
    u + dt a(u) = |b| (a: the law's deceleration) to round-off; u grows with |b|; thin
    films (h down to 1e-12 m) give finite speeds."""
    P = law_parameters(law)
    kernels = FRICTION_LAWS[law].kernels
    law_speed, accel = kernels.speed, basal_accel(kernels)
    law = law_block(P, S.LAW)
    rng = np.random.default_rng(3)
    gz = P[S.G_Z]
    for _ in range(2000):
        h = 10.0 ** rng.uniform(-12, 0.5)
        dt = 10.0 ** rng.uniform(-5, -1)
        a_static = dt * accel(law, h, gz, h, 0.0)
        b = a_static * rng.uniform(0.0, 3.0) + (rng.uniform(0, 5) if rng.random() < 0.3
                                                 else 0.0)
        s = law_speed(b, h, gz, h, dt, law)
        assert np.isfinite(s) and s >= 0.0
        if b <= a_static:
            assert s == 0.0
        else:
            assert s > 0.0 or b - a_static < 1e-300
            residual = s + dt * accel(law, h, gz, h, s) - b
            assert abs(residual) <= 1e-12 * b
            assert law_speed(b * 1.01, h, gz, h, dt, law) >= s


@pytest.mark.parametrize("law", LAWS)
def test_two_layer_root_balances_the_total_momentum(law):
    """The coupled stage (32) with a bed law: a sliding lower layer's speed balances the
    total momentum m1 (u1 - b1) + m2 (u2 - b2) + dt B(u2) = 0, and a stuck one is held
    by the static bound."""
    P = law_parameters(law, pdeflow.TwoLayerGranular)
    kernels = FRICTION_LAWS[law].kernels
    solve, accel = friction_two_layer_law(kernels), basal_accel(kernels)
    law = law_block(P, T.LAW)
    rng = np.random.default_rng(5)
    g, r = P[T.G_Z], P[T.R]
    for _ in range(1000):
        h1, h2 = 10.0 ** rng.uniform(-6, 0, 2)
        dt = 10.0 ** rng.uniform(-4, -1)
        b1, b2 = rng.normal(0, 2, 2)
        m1 = r * h1
        kdt = dt * 0.65 * r * g * h1 * P[T.TAN_INT]
        u1, u2 = solve(b1, b2, m1, h2, kdt, dt * 0.03, dt, g, h1 + h2, law)
        assert np.isfinite(u1) and np.isfinite(u2)
        w = m1 + h2
        if u2 == 0.0:
            push = h2 * b2 + m1 * (b1 - u1)
            assert abs(push) <= dt * accel(law, h1 + h2, g * w, 1.0, 0.0) * (
                1 + 1e-12)
        else:
            bdt = dt * accel(law, h1 + h2, g * w, 1.0, abs(u2)) * np.sign(u2)
            balance = m1 * (u1 - b1) + h2 * (u2 - b2) + bdt
            assert abs(balance) <= 1e-10 * (m1 * abs(b1) + h2 * abs(b2) + abs(bdt))


@pytest.mark.parametrize("law", LAWS)
@pytest.mark.parametrize("two_layer", [False, True])
def test_numba_and_numpy_rates_agree_for_every_law(law, two_layer):
    rng = np.random.default_rng(2)
    n = 40
    g = grid(n)
    h = np.where(rng.random(n) < 0.2, 0.0, 10.0 ** rng.uniform(-4, 0, n))
    u = rng.normal(0, 1, n) * (h > 0)
    u[::6] = 0.0
    if two_layer:
        eq = pdeflow.TwoLayerGranular(bc=("wall", "open"), theta_deg=25, friction_law=law)
        st = eq.make_state(g, h1=0.4 * h, u1=1.2 * u, h2=0.6 * h, u2=u)
    else:
        eq = pdeflow.SingleLayerGranular(bc=("open", "wall"), theta_deg=25,
                                         friction_law=law)
        st = eq.make_state(g, h=h, u=u)
    numpy_rate = eq.evolution_rate(st).data
    numba_rate = eq.make_evolution_rate(st, get_backend("numba"))(st.data, 0.0)
    np.testing.assert_allclose(numba_rate, numpy_rate, rtol=1e-11, atol=1e-11)
    coulomb = type(eq)(bc=eq.bc, theta_deg=25).evolution_rate(st).data
    assert np.abs(numpy_rate - coulomb).max() > 1e-3  # the law is really used


def test_coulomb_block_and_law_parameters_are_validated():
    P = pdeflow.SingleLayerGranular(phi_b_deg=30.0).parameter_array()
    assert P[S.LAW + L.LAW_MU1] == P[S.TAN_B]
    assert not P[S.LAW + 1:S.LAW + L.N_LAW].any()  # no code: the kernels carry the law
    assert len(law_block(P, S.LAW)) == L.N_LAW  # what the kernels read is the block
    with pytest.raises(ValueError, match=r"^friction_law must be one of"):
        pdeflow.SingleLayerGranular(friction_law="bingham")
    with pytest.raises(ValueError, match=r"^pouliquen_L must lie in \(0, inf\) m"):
        pdeflow.TwoLayerGranular(pouliquen_L=0.0)
    with pytest.raises(ValueError, match=r"^delta2_deg must lie in \[20.9, 90\) deg"):
        pdeflow.TwoLayerGranular(delta2_deg=10.0)
    with pytest.raises(ValueError, match=r"^voellmy_xi must lie in"):
        pdeflow.SingleLayerGranular(voellmy_xi=-1.0)


def _law_code(kernel) -> bool:
    """True for a kernel of a basal law (:mod:`pdeflow.numerics.rheology`,
    :mod:`pdeflow.models.two_layer.laws`)."""
    return kernel.py_func.__module__ in ("pdeflow.numerics.rheology",
                                         "pdeflow.models.two_layer.laws")


def test_each_run_compiles_its_own_law_only():
    """A Coulomb run uses the model's bundle, whose stepping kernels call no law kernel;
    a run with a law uses that law's bundle (one per law), whose stage calls that law's
    step and no other law's: the law reaches the kernels as compiled-in constants only
    (the parameter vector holds no code of it)."""
    from pdeflow.numerics import compile_parallel

    def tree(bundle) -> list:
        found: dict = {}
        for k in (bundle.sources, bundle.predictor, bundle.mol_sources):
            compile_parallel._call_tree(k, found)
        return list(found.values())

    for cls in (pdeflow.SingleLayerGranular, pdeflow.TwoLayerGranular):
        coulomb = cls()
        assert coulomb.kernels is coulomb.system.kernels
        assert not any(map(_law_code, tree(coulomb.kernels)))
        bundles = {id(cls(friction_law=law).kernels) for law in LAWS}
        assert len(bundles) == len(LAWS) and id(coulomb.kernels) not in bundles
        for law in LAWS:
            found = tree(cls(friction_law=law).kernels)
            steps = {FRICTION_LAWS[name].kernels.speed for name in LAWS}
            assert [k for k in found if k in steps] == [FRICTION_LAWS[law].kernels.speed]


def test_rheology_report_generator_runs(tmp_path):
    """docs/generate/rheology.py on coarse grids and two aspect ratios per geometry: the
    report names the closest law of each geometry and model, the figures exist, the
    cache holds one row per point and a second call runs nothing (--no-runs renders the
    same page)."""
    import os
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    cmd = [sys.executable, str(root / "docs" / "generate" / "rheology.py"), "--out",
           str(tmp_path), "--planar-grids", "0.05", "0.025", "--axisymmetric-grids",
           "0.02", "0.01", "--planar-ratios", "2", "4", "--axisymmetric-ratios", "1", "2",
           "--planar-length", "12", "--axisymmetric-length", "1.5"]
    env = {**os.environ, "PYTHONPATH": str(root)}
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=600, env=env)
    assert proc.returncode == 0, proc.stderr[-2000:]
    text = (tmp_path / "rheology.md").read_text()
    for geometry in ("planar", "axisymmetric"):
        for model in ("single_layer", "two_layer"):
            assert f"* **{geometry}, {model}**: closest is **" in text
    for fig in ("rheology_runout", "rheology_axisymmetric", "rheology_convergence"):
        assert (tmp_path / "figures" / f"{fig}.png").stat().st_size > 1000
    rows = (tmp_path / "rheology" / "sweep.csv").read_text().splitlines()
    assert len(rows) == 1 + 2 * 2 * (5 * 2 + 4 * 2)  # header; grids x a x (laws x models)
    again = subprocess.run([*cmd, "--no-runs"], capture_output=True, text=True,
                           timeout=600, env=env)
    assert again.returncode == 0, again.stderr[-2000:]
    assert (tmp_path / "rheology" / "sweep.csv").read_text().splitlines() == rows
    assert (tmp_path / "rheology.md").read_text() == text


def test_rheology_page_is_the_rendering_of_its_numbers():
    """docs/rheology.md is rheology_page.render_page of docs/rheology/numbers.json (no
    hand-typed results), and every figure it shows exists."""
    import json
    from pathlib import Path

    from tests.helpers import generator_modules

    root = Path(__file__).resolve().parents[1]
    numbers = json.loads((root / "docs" / "rheology" / "numbers.json").read_text())
    page = (root / "docs" / "rheology.md").read_text()
    with generator_modules("rheology_page") as (rheology_page,):
        assert page == rheology_page.render_page(numbers, numbers["figures"])
    for fig in numbers["figures"].values():
        assert (root / "docs" / fig).is_file()


def test_case_key_reaches_the_run_and_its_stored_variant():
    """``single_layer.friction_law`` in a case: the run uses the law, its parameters are
    in the metadata, and the stored variant names it (a Coulomb run's variant is as
    before, without it)."""
    from pdeflow.cases import load_case
    from pdeflow.storage import run_metadata

    root = __import__("pathlib").Path(__file__).resolve().parents[1]
    case_file = root / "cases" / "collapse_sweep.toml"
    sets = ["grid.dx=0.05", "case.models=['single_layer']"]
    coulomb = load_case(case_file, sets)
    law = load_case(case_file, [*sets, "single_layer.friction_law='pouliquen'"])
    assert law.make_pde("single_layer").parameters.friction_law == "pouliquen"
    meta = run_metadata(law, "single_layer")
    assert "friction_law=pouliquen" in meta["variant"]
    assert "friction_law" not in run_metadata(coulomb, "single_layer")["variant"]


def test_a_study_over_laws_warms_every_law_bundle(tmp_path):
    """A study file choosing among basal laws: the kernels its workers will need (the
    Coulomb bundle and the chosen law's bundle) are among those its process prepares."""
    from pathlib import Path

    from pdeflow.study.evaluate import study_steppers
    from pdeflow.study.spec import load_study

    root = Path(__file__).resolve().parents[1]
    study = tmp_path / "laws.toml"
    study.write_text(
        '[study]\nname = "laws"\n'
        f'case = "{(root / "cases" / "paper_5_1_dam_break.toml").as_posix()}"\n'
        'set = ["grid.dx=0.05", "case.models=[\'single_layer\']"]\n'
        'design = "grid"\nquantities = ["single_layer.runout"]\n'
        '[parameters]\n"single_layer.friction_law" = { choices = ["coulomb", "voellmy"] }\n')
    spec = load_study(study)
    kernels = {k for s in study_steppers(spec) for k in s.kernels}
    system = pdeflow.SingleLayerGranular.system
    assert system.kernels.sources in kernels
    assert system.law_kernels(FRICTION_LAWS["voellmy"].kernels).sources in kernels


def _cached_rows():
    from pathlib import Path

    from tests.helpers import generator_modules

    root = Path(__file__).resolve().parents[1]
    with generator_modules("rheology_runs") as (runs,):
        return runs, runs.read_cache(root / "docs" / "rheology" / "sweep.csv")


def _check_reruns(points):
    runs, rows = _cached_rows()
    cached = {runs.key(r): r for r in rows}
    for p in points:
        new = runs.measure(p)
        old = cached[p]
        assert new["r"] == old["r"] and new["steps"] == old["steps"], (p, new, old)
        assert new["at_rest"] and old["at_rest"], p


def test_cached_law_sweep_rows_are_what_the_code_gives():
    """Three points of docs/rheology/sweep.csv (planar and radial, both models, three
    laws) run again give the cached run-out and step count exactly."""
    _check_reruns([("planar", "single_layer", "coulomb", 0.01, 2.0),
                   ("planar", "two_layer", "pouliquen", 0.01, 4.0),
                   ("axisymmetric", "single_layer", "mu_i", 0.00125, 1.0)])


@pytest.mark.slow
def test_cached_law_sweep_coarsest_grids_rerun():
    """Every point of the coarsest planar and radial grids of docs/rheology/sweep.csv
    run again gives the cached run-out exactly (minutes)."""
    runs, _ = _cached_rows()
    _check_reruns([p for p in runs.all_points()
                   if p[3] == runs.GRIDS[p[0]][0]])
