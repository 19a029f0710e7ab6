"""Stability under stress (issue 5): random physical states and parameters, and extremes.

Property-based tests (hypothesis) draw the parameters, the scheme and the initial state;
the arrays of a state come from a numpy generator seeded by hypothesis, so that every
failure is reproducible from the printed example. Invariants after *every* step:

* no NaN or inf and no negative depth (the solver would raise SimulationBlowUp);
* dry layers have zero momentum;
* rho1 h1 + rho2 h2 summed over the cells is conserved to round-off (walls);
* where both layers are wetter than the dry tolerance, the state after the step (i.e.
  after the hyperbolicity stage) is hyperbolic by the exact test (mode 1);
* states at rest below their friction angles stay at rest, exactly.

The default test command runs the ``pdeflow-default`` profile (a bounded, derandomised
number of examples, reproducible); the long run, recorded in docs/stability.md, is::

    PDEFLOW_HYPOTHESIS_PROFILE=pdeflow-long python -m pytest tests/test_stress.py -q \
        -p no:randomly -m "slow or not slow" --hypothesis-show-statistics

The extreme configurations run in fast forms here; their heavy forms are marked ``slow``
(deselected by default; ``python -m pytest -m slow tests/test_stress.py``).
"""

from __future__ import annotations

import contextlib
import math
import os
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, note, settings
from hypothesis import strategies as st
from pde import CartesianGrid, PolarSymGrid

import pdeflow
from pdeflow import FVSplitSolver
from pdeflow.analysis.positivity import FLUXES as POSITIVITY_FLUXES
from pdeflow.analysis.positivity import SCHEMES as POSITIVITY_SCHEMES
from pdeflow.metrics import mass
from pdeflow.models.two_layer.hyperbolicity import is_hyperbolic
from pdeflow.numerics import layout as L
from pdeflow.variant import HYPERBOLICITY

settings.register_profile(
    "pdeflow-default", max_examples=150, deadline=None, derandomize=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
    print_blob=True)
settings.register_profile(
    "pdeflow-long", max_examples=10_000, deadline=None, derandomize=False,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
    print_blob=True)
PROFILE = settings.get_profile(os.environ.get("PDEFLOW_HYPOTHESIS_PROFILE",
                                              "pdeflow-default"))

EPS = np.finfo(float).eps
T_FAR = 1e9  # an end time [s] never reached: steps are limited by max_steps=1
SCHEMES = [("hll", "first-order"), ("rusanov", "first-order"), ("ifcp", "first-order"),
           ("hll", "muscl")]


# --- helpers -----------------------------------------------------------------------------

@dataclass
class Scenario:
    """A drawn test case: model, parameters, scheme and initial profiles."""

    two_layer: bool
    params: dict[str, Any]
    scheme: dict[str, str]
    splitting: str
    cfl: float
    length: float
    profiles: dict[str, np.ndarray] = field(repr=False)
    geometry: str = "planar"
    width: float = 0.0
    """extent across the slope [m] of a 2D state (profiles of shape (nx, ny))"""

    def make(self):
        shape = next(iter(self.profiles.values())).shape
        if len(shape) == 2:
            grid = CartesianGrid([[0.0, self.length], [0.0, self.width]], list(shape))
        elif self.geometry == "axisymmetric":
            grid = PolarSymGrid((0.0, self.length), shape[0])
        else:
            grid = CartesianGrid([[0.0, self.length]], shape[0])
        cls = pdeflow.TwoLayerGranular if self.two_layer else pdeflow.SingleLayerGranular
        eq = cls(bc=("wall", "wall"), **self.scheme, **self.params)
        return eq, eq.make_state(grid, **self.profiles)


def stepper_for(eq, state, cfl: float, splitting: str = "lie"):
    """One-step-per-call fv-split stepper: ``stepper(state, t, T_FAR) -> t``."""
    solver = FVSplitSolver(eq, cfl=cfl, splitting=splitting, stop_at_rest=False,
                           max_steps=1)
    return solver.make_stepper(state)


def total_mass(eq, q: np.ndarray, cells: float | np.ndarray = 1.0) -> float:
    """sum(rho1 h1 + rho2 h2) / rho2 over cells of equal width (or of the volumes
    ``cells``) [m, or m^3 with volumes in m^2 on a 2D grid]. A 2D state (rows h, hu, hv
    per layer) is summed as the 1D layout of its rows h, hu (mass reads the depth rows
    0, 2, ...), its cells flattened as the metric's volumes are."""
    if q.ndim == 3:
        q = np.delete(q, np.s_[2::3], axis=0).reshape(2 * (q.shape[0] // 3), -1)
    return mass(q, cells, eq.system.densities(eq.parameters))


def non_hyperbolic_cells(eq, q: np.ndarray) -> list[int]:
    """Cells where both layers are wet and the exact test (mode 1) fails."""
    P = eq.parameter_array()
    dry = eq.parameters.dry_tolerance
    r = eq.parameters.density_ratio
    bad = []
    for i in np.nonzero((q[0] > dry) & (q[2] > dry))[0]:
        u1 = q[1, i] / q[0, i]
        u2 = q[3, i] / q[2, i]
        if not is_hyperbolic(q[0, i], q[2, i], u1, u2, P[0], r, 1):
            bad.append(int(i))
    return bad


def check_step_invariants(eq, q: np.ndarray, mass0: float, steps: int,
                          cells: float | np.ndarray = 1.0) -> None:
    """Finite, depths >= 0, dry layers without momentum, mass to round-off and (1D
    two-layer) hyperbolic wet cells; ``q`` a 1D state (rows h, hu per layer) or a 2D one
    (rows h, hu, hv per layer: q.ndim = 1 + axes rows per layer)."""
    rows = q.ndim
    assert np.all(np.isfinite(q))
    assert np.all(q[::rows] >= 0.0)
    dry = eq.parameters.dry_tolerance
    for k in range(0, q.shape[0], rows):
        assert np.all(q[k + 1:k + rows][:, q[k] <= dry] == 0.0)
    # round-off: a few ulps of the total per step (measured worst case: 2e-15 per step
    # in 1D; 2D: tests/test_stress_2d.py)
    assert abs(total_mass(eq, q, cells) - mass0) <= 16 * EPS * steps * mass0
    if rows == 2 and eq.system.has_fextra and eq.parameters.hyperbolicity != "none":
        assert non_hyperbolic_cells(eq, q) == []


def check_single_layer_heap_stays_at_rest(h: np.ndarray, reconstruction: str) -> None:
    """A single-layer heap h [m] on cells of 0.1 m (walls, phi_B = 10 deg, HLL, CFL 0.5)
    whose one-sided slopes are all below 95 % of tan(phi_B) stays at rest, bit for bit,
    for 10 steps."""
    assert np.abs(np.diff(h)).max() / 0.1 < 0.95 * math.tan(math.radians(10.0))
    eq, state = Scenario(False, {"phi_b_deg": 10.0}, {"flux": "hll",
                                                      "reconstruction": reconstruction},
                         "lie", 0.5, h.size / 10, {"h": h}).make()
    stepper = stepper_for(eq, state, 0.5)
    t = 0.0
    for _ in range(10):
        t = stepper(state, t, T_FAR)
    np.testing.assert_array_equal(state.data[0], h)
    assert np.all(state.data[1] == 0.0)

@contextlib.contextmanager
def no_swallowed_exceptions():
    """Fail if a compiled kernel raised inside the block: numba cannot propagate an
    exception out of a kernel called through a function pointer (the stepper's
    first-class kernels), writes it to ``sys.unraisablehook`` ("Exception ignored in
    CPUContext") and goes on with what the kernel left, e.g. a source stage stopped
    half-way (tests/test_stress_2d.py: a ZeroDivisionError in the 2D friction's
    Newton step left dry cells with momentum)."""
    swallowed: list[BaseException | None] = []
    hook = sys.unraisablehook
    sys.unraisablehook = lambda unraisable: swallowed.append(unraisable.exc_value)
    try:
        yield
    finally:
        sys.unraisablehook = hook
    assert not swallowed, f"exceptions swallowed in compiled kernels: {swallowed!r}"


def check_invariants_step_by_step(eq, state, cfl: float, splitting: str,
                                  n_steps: int) -> None:
    """Advance ``state`` in place one fv-split step at a time, checking the invariants
    (check_step_invariants), that time never goes back and that no kernel raised
    (:func:`no_swallowed_exceptions`) after every step."""
    cells = eq.metric(state.grid).cells
    mass0 = total_mass(eq, state.data, cells)
    stepper = stepper_for(eq, state, cfl, splitting)
    t = 0.0
    for k in range(1, n_steps + 1):
        with no_swallowed_exceptions():
            t_new = stepper(state, t, T_FAR)
        assert t_new >= t
        t = t_new
        check_step_invariants(eq, state.data, mass0, k, cells)

def random_depth(rng: np.random.Generator, shape: int | tuple[int, ...], scale: float,
                 dry_fraction: float):
    """Depths [m] in [0, scale) on ``shape`` cells (n, or (nx, ny)) with isolated dry
    cells and, sometimes, a dry gap of 1 to 3 cells along each axis (a dry patch in 2D)."""
    shape = (shape,) if isinstance(shape, int) else tuple(shape)
    h = scale * rng.random(shape)
    h[rng.random(shape) < dry_fraction] = 0.0
    if min(shape) > 6 and rng.random() < 0.5:
        gap = []
        for n in shape:  # the 1D draws, in the 1D order, along each axis
            a = int(rng.integers(0, n - 3))
            gap.append(slice(a, a + int(rng.integers(1, 4))))
        h[tuple(gap)] = 0.0
    return h


def thin_films(draw, rng: np.random.Generator, h: np.ndarray, axes: int) -> np.ndarray:
    """``h`` [m] (2D states: ``axes=2``) with a random share of its cells (up to 1/2)
    thinned by 1 to 6 decades, so that films lie next to deep cells within one state;
    1D states unchanged (and no draws: the 1D examples stay those recorded)."""
    if axes == 1:
        return h
    films = rng.random(h.shape) < draw(st.sampled_from([0.0, 0.2, 0.5]))
    h[films] *= 10.0 ** -rng.uniform(1.0, 6.0, int(films.sum()))
    return h


def rotate_across(draw, rng: np.random.Generator, profiles: dict[str, np.ndarray]) -> None:
    """Turn the drawn (1D) velocities u, u1, u2 [m/s] of 2D profiles into vectors of the
    same length, in place: all along x (v = 0: the 2D kernels' 1D arithmetic), all along
    y, or each cell at its own random angle (both layers of a cell turned together, so
    the shear du keeps its length)."""
    along = draw(st.sampled_from(["x", "y", "any"]))
    shape = next(iter(profiles.values())).shape
    if along == "any":
        a = rng.uniform(0.0, 2.0 * math.pi, shape)
        cos, sin = np.cos(a), np.sin(a)
    else:  # exactly 0 across: cos(pi/2) is not
        cos, sin = (1.0, 0.0) if along == "x" else (0.0, 1.0)
    for u, v in (("u", "v"), ("u1", "v1"), ("u2", "v2")):
        if u in profiles:
            speed = profiles[u]
            profiles[u], profiles[v] = cos * speed, sin * speed


def cfl_numbers(reconstruction: str) -> st.SearchStrategy[float]:
    """CFL numbers up to 0.9; up to 0.5 for MUSCL, whose update is positive only there
    (a MUSCL run at CFL 0.75 goes negative: test_failures / docs/stability.md)."""
    return st.floats(0.05, 0.5 if reconstruction == "muscl" else 0.9)


@st.composite
def scenarios(draw, axes: int = 1, **fixed) -> Scenario:
    """Random but physical states and parameters (see the module docstring); on a 1D
    grid (planar or axisymmetric), or with ``axes=2`` on a 2D CartesianGrid of 8-16 x
    6-12 cells (tests/test_stress_2d.py), where the velocities get directions
    (:func:`rotate_across`), the two-layer restoration its directions and the scheme a
    limiter. The 2D draws only add to the 1D ones, so the 1D examples are those recorded
    before. ``fixed`` sets choices instead of drawing them: ``two`` (bool), ``splitting``
    and (2D only) ``flux`` and ``reconstruction`` with ``limiter``."""

    def choose(key: str, strategy: st.SearchStrategy) -> Any:
        return fixed[key] if key in fixed else draw(strategy)

    two = fixed["two"] if "two" in fixed else \
        draw(st.booleans()) or draw(st.booleans())  # 3/4 two-layer
    n = draw(st.integers(3, 48)) if axes == 1 else \
        (draw(st.integers(8, 16)), draw(st.integers(6, 12)))
    seed = draw(st.integers(0, 2**32 - 1))
    scale = 10.0 ** draw(st.floats(-8.0, 0.5))  # layers from 1e-8 m to ~3 m
    dry_fraction = draw(st.sampled_from([0.0, 0.2, 0.5]))
    v_scale = 10.0 ** draw(st.floats(-3.0, 1.5))  # velocities up to ~30 m/s
    phi_b = draw(st.floats(10.0, 45.0))
    params: dict[str, Any] = {
        "phi_b_deg": phi_b,
        "theta_deg": phi_b * draw(st.floats(0.0, 1.5)),  # up to and beyond phi_b
    }
    rng = np.random.default_rng(seed)
    length = 10.0 ** draw(st.floats(-2.0, 1.5))
    if two:
        r = draw(st.floats(0.05, 0.99))
        params.update(
            density_ratio=r, phi_int_deg=draw(st.floats(10.0, 45.0)),
            k=draw(st.floats(0.0, 0.999)), c=10.0 ** draw(st.floats(-4.0, 1.0)),
            hyperbolicity=draw(st.sampled_from(["exact", "bound"])),
            exchange_closure=draw(st.sampled_from(["paper", "relaxed", "none"])),
            du_reg=draw(st.sampled_from([0.0, 0.1])))
        if axes == 2:
            params.update(hyperbolicity=draw(st.sampled_from(HYPERBOLICITY)),
                          hyperbolicity_directions=draw(st.sampled_from(["all", "flow"])))
        h1 = thin_films(draw, rng, random_depth(rng, n, scale, dry_fraction), axes)
        h2 = thin_films(draw, rng, random_depth(rng, n, scale, dry_fraction), axes)
        u2 = v_scale * rng.standard_normal(n)
        # relative velocity up to 4x the upper edge F_R of the non-hyperbolic band
        fr = np.sqrt(2 * 9.81 * (h1 + h2) * (1 + np.sqrt(r)))  # F_R (see hyperbolicity)
        du = draw(st.floats(0.0, 4.0)) * fr * rng.choice([-1.0, 1.0], n)
        profiles = {"h1": h1, "u1": u2 + du + 0.1 * v_scale * rng.standard_normal(n),
                    "h2": h2, "u2": u2}
    else:
        profiles = {"h": thin_films(draw, rng, random_depth(rng, n, scale, dry_fraction),
                                    axes),
                    "u": v_scale * rng.standard_normal(n)}
    if axes == 2:
        rotate_across(draw, rng, profiles)
        # every flux with first order and MUSCL with each limiter (the positivity
        # stress's lists); IFCP too: its steps that are not positive are redone with HLL
        flux = choose("flux", st.sampled_from(POSITIVITY_FLUXES))
        rec, limiter = ((fixed["reconstruction"], fixed["limiter"]) if "limiter" in fixed
                        else draw(st.sampled_from(POSITIVITY_SCHEMES)))
        scheme = {"flux": flux, "reconstruction": rec, "limiter": limiter}
    else:
        # IFCP too: its steps that are not positive are redone with HLL
        flux, rec = draw(st.sampled_from(SCHEMES))
        scheme = {"flux": flux, "reconstruction": rec}
    splitting = choose("splitting", st.sampled_from(["lie", "strang"]))
    if splitting == "strang" and two and axes == 1:
        # known bug (docs/stability.md, test_strang_step_keeps_the_cfl_condition): Strang
        # takes dt before its first half source step; erosion in that half step turns
        # lower-layer material into upper-layer material 1/r times deeper, the wave
        # speed grows and the advection breaks the CFL condition. Without exchange the
        # half step only brakes, or accelerates by gravity, which dt accounts for.
        # Fixed since (the stepper undoes such a half step and retries with a shorter
        # dt: docs/stability.md, finding 2); the 1D draws keep the restriction, so that
        # their examples stay those recorded, the 2D ones run Strang with exchange.
        params["exchange_closure"] = "none"
    if axes == 2:
        # cells from 1/3 to 3 times as wide across as along the slope
        width = length * n[1] / n[0] * 10.0 ** draw(st.floats(-0.5, 0.5))
        return Scenario(two, params, scheme, splitting, draw(cfl_numbers(rec)), length,
                        profiles, "planar", width)
    return Scenario(two, params, scheme, splitting, draw(cfl_numbers(rec)), length,
                    profiles, draw(st.sampled_from(["planar", "axisymmetric"])))


@st.composite
def law_parameters(draw, law: str) -> dict[str, Any]:
    """``friction_law=law`` and that law's constants drawn over the ranges of the app's
    sliders (pdeflow/app/controls.py, KNOBS: the ranges the docs offer a user; lengths
    and xi log-uniform), with delta1 <= delta2 as the validation requires; Coulomb's
    only constant is phi_b_deg, drawn with the state."""
    params: dict[str, Any] = {"friction_law": law}
    if law in ("pouliquen", "mu_i"):
        d1 = draw(st.floats(10.0, 32.0))
        params.update(delta1_deg=d1, delta2_deg=draw(st.floats(max(d1, 21.0), 45.0)))
    if law == "pouliquen":
        params.update(pouliquen_L=10.0 ** draw(st.floats(-4.0, math.log10(5e-3))),
                      pouliquen_beta=draw(st.floats(0.05, 0.5)))
    elif law == "mu_i":
        params.update(mu_i_I0=draw(st.floats(0.05, 1.0)),
                      grain_diameter=10.0 ** draw(st.floats(-4.0, math.log10(5e-3))),
                      packing_fraction=draw(st.floats(0.4, 0.65)))  # no slider: 0.6 +-
    elif law == "voellmy":
        params.update(voellmy_mu=draw(st.floats(0.0, 0.8)),
                      voellmy_xi=10.0 ** draw(st.floats(2.0, 4.0)))
    return params


# --- property-based tests ------------------------------------------------------------------

@PROFILE
@given(scenarios(), st.integers(5, 30))
def test_random_states_keep_the_invariants(scenario, n_steps):
    eq, state = scenario.make()
    note(repr(scenario))
    note({k: v.tolist() for k, v in scenario.profiles.items()})
    check_invariants_step_by_step(eq, state, scenario.cfl, scenario.splitting, n_steps)


@settings(PROFILE, max_examples=min(PROFILE.max_examples, 60))
@given(scenarios(), st.sampled_from(["pouliquen", "mu_i", "voellmy"]),
       st.integers(5, 30))
def test_random_states_keep_the_invariants_with_every_basal_law(scenario, law, n_steps):
    """The same random states with a rate-dependent basal law (issue 23): positivity,
    mass, dry cells at rest and hyperbolicity after every step."""
    scenario.params["friction_law"] = law
    eq, state = scenario.make()
    note(repr(scenario))
    check_invariants_step_by_step(eq, state, scenario.cfl, scenario.splitting, n_steps)


@st.composite
def rest_states(draw) -> Scenario:
    """Heaps whose surface is below the friction angle in every cell, with a margin.

    A heap at rest feels, in cell i, the centred surface slope
    S = (E_{i+1} - E_{i-1}) / (2 dx) (E = h2 + r h1, walls mirror the ends, dry cells
    count as E = 0). With Lie splitting the implicit Coulomb stage then holds it iff
    |S - tan(theta)| <= tan(phi_B). With Strang splitting only the second half step of
    friction acts against the pressure impulse of the whole advection step, so the
    condition is |S - tan(theta)/2| <= tan(phi_B)/2: Strang holds heaps only up to about
    half the friction angle (docs/stability.md). A random walk whose one-sided slopes lie
    within 95 % of these bounds (clipped at zero: dry gaps) satisfies them.
    """
    n = draw(st.integers(3, 60))
    seed = draw(st.integers(0, 2**32 - 1))
    dx = 10.0 ** draw(st.floats(-8.0, -0.5))  # heaps from ~1e-8 m to metres
    phi_b = draw(st.floats(10.0, 45.0))
    theta = phi_b * draw(st.floats(0.0, 0.9))
    tan_b = math.tan(math.radians(phi_b))
    tan_t = math.tan(math.radians(theta))
    splitting = draw(st.sampled_from(["lie", "strang"]))
    half = 0.5 if splitting == "strang" else 1.0
    lo, hi = half * (tan_t - 0.95 * tan_b), half * (tan_t + 0.95 * tan_b)
    rng = np.random.default_rng(seed)
    e = np.empty(n)
    e[0] = dx * hi * rng.random() * 3
    for i in range(1, n):
        e[i] = max(e[i - 1] + dx * rng.uniform(lo, hi), 0.0)
    kind = draw(st.sampled_from(["single", "lower only", "upper on flat lower"]))
    flux, rec = draw(st.sampled_from(SCHEMES))
    params: dict[str, Any] = {"phi_b_deg": phi_b, "theta_deg": theta}
    if kind == "single":
        return Scenario(False, params, {"flux": flux, "reconstruction": rec}, splitting,
                        draw(cfl_numbers(rec)), n * dx, {"h": e})
    params.update(density_ratio=draw(st.floats(0.05, 0.99)),
                  phi_int_deg=draw(st.floats(10.0, 45.0)), k=draw(st.floats(0.0, 0.999)),
                  c=10.0 ** draw(st.floats(-4.0, 1.0)))
    if kind == "lower only":
        profiles = {"h1": np.zeros(n), "h2": e}
    else:  # uniform layers on a horizontal bed: the upper layer is deposited at once
        params["theta_deg"] = 0.0
        h2 = np.full(n, e.max() + dx)
        profiles = {"h1": np.full(n, h2[0] * 10.0 ** draw(st.floats(-2.0, 1.0))),
                    "h2": h2}
    return Scenario(True, params, {"flux": flux, "reconstruction": rec}, splitting,
                    draw(cfl_numbers(rec)), n * dx, profiles)


@PROFILE
@given(rest_states())
def test_states_at_rest_stay_at_rest(scenario):
    eq, state = scenario.make()
    note(repr(scenario))
    note({k: v.tolist() for k, v in scenario.profiles.items()})
    mass0 = total_mass(eq, state.data)
    stepper = stepper_for(eq, state, scenario.cfl, scenario.splitting)
    t = stepper(state, 0.0, T_FAR)
    after_first = state.data.copy()
    assert np.all(after_first[1::2] == 0.0)
    if "h1" in scenario.profiles and scenario.profiles["h1"].any():
        # the paper's closure deposits a resting upper layer at once (M -> -inf at du=0)
        assert np.all(after_first[0] == 0.0)
    else:
        np.testing.assert_array_equal(after_first, state.data)
    for _ in range(30):
        t = stepper(state, t, T_FAR)
        np.testing.assert_array_equal(state.data, after_first)
    assert abs(total_mass(eq, state.data) - mass0) <= 16 * EPS * mass0


def test_strang_step_keeps_the_cfl_condition():
    """Found by test_random_states_keep_the_invariants (long profile)."""
    scenario = Scenario(
        True, {"phi_b_deg": 10.0, "theta_deg": 15.0, "density_ratio": 0.5,
               "phi_int_deg": 10.0, "k": 0.0, "c": 1.0},
        {"flux": "hll", "reconstruction": "first-order"}, "strang", 0.5, 10.0,
        {"h1": np.array([0.00636962, 0.00269787, 0.00040974]),
         "u1": np.array([-2.35666079, -0.17762861, -1.14165961]),
         "h2": np.array([0.00606636, 0.00729497, 0.00543625]),
         "u2": np.array([-2.32503077, -0.21879166, -1.24591095])})
    eq, state = scenario.make()
    check_invariants_step_by_step(eq, state, scenario.cfl, scenario.splitting, 5)


def test_strang_step_keeps_the_cfl_condition_under_erosion():
    """Found by test_random_states_keep_the_invariants (long profile, seed 7), after the
    gravity fix above. dt is chosen before the first half source step; here (flat bed,
    r = 0.0625) that half step erodes the whole lower layer of cell 1 into the upper
    one, 1/r = 16 times deeper (h1 0.027 -> 1.19 m), sqrt(g H) triples, and the
    advection broke the CFL condition (h1 = -2.4e-3 m in step 1) until the stepper
    learnt to undo such a half step and retry with a shorter dt."""
    params = {"phi_b_deg": 10.0, "density_ratio": 0.0625, "phi_int_deg": 10.0, "k": 0.0,
              "c": 1.0}
    profiles = {"h1": np.array([0.0, 0.02697867, 0.00409735]),
                "u1": np.array([1.19617691, -1.56726095, -0.32841434]),
                "h2": np.array([0.06066358, 0.07294966, 0.0]),
                "u2": np.array([-0.02325031, -0.00218792, -0.01245911])}
    for splitting in ("lie", "strang"):
        eq, state = Scenario(True, params, {"flux": "hll"}, splitting, 0.75, 1.0,
                             profiles).make()
        check_invariants_step_by_step(eq, state, 0.75, splitting, 5)


def test_muscl_heap_with_a_kink_stays_at_rest():
    """Found by test_states_at_rest_stay_at_rest (long profile) after the dry-edge fix:
    MUSCL overshot the hydrostatic force at a kink of a heap. Cell 1 of h = [0.0291,
    0.0252, 0.0419, 0.0580] m (dx = 0.1 m, wall on the right) felt 0.5 (h_i^+ h_{i+1}^-
    - h_i^- h_{i-1}^+) / (h_i dx) = 0.24, steeper than any slope of the data (<= 0.167 <
    tan 10 deg = 0.176), and the heap slumped. Cells at rest with their neighbours are
    now reconstructed at first order."""
    h = np.array([0.0290996, 0.02520256, 0.04186015, 0.05796915])
    for rec in ("first-order", "muscl"):
        check_single_layer_heap_stays_at_rest(h, rec)


def test_ifcp_steps_that_are_not_positive_are_redone_with_hll():
    """Found by test_random_states_keep_the_invariants (long profile): IFCP reduces to
    Roe's scheme for one layer, and Roe's linearisation gives negative depths where two
    cells move apart fast (no positivity for any CFL number); HLL and Rusanov, whose
    wave speeds bound the physical ones, stay positive on the same state. The stepper
    therefore redoes such an IFCP step with HLL and counts it."""
    from pdeflow.numerics.splitting import advect_step_function, scheme_stepper

    profiles = {"h": np.array([0.51182162, 0.9504637, 0.14415961]),
                "u": np.array([-5.36953235, 5.81118104, 3.64572396])}
    for flux in ("ifcp", "hll", "rusanov"):
        eq, state = Scenario(False, {"phi_b_deg": 10.0}, {"flux": flux}, "lie", 0.5, 1.0,
                             profiles).make()
        solver = FVSplitSolver(eq, cfl=0.5, stop_at_rest=False, max_steps=1)
        stepper = solver.make_stepper(state)
        t = 0.0
        for _ in range(5):
            q = state.data.copy()
            n = q.shape[1]
            diag = eq.new_diagnostics(n)
            # the bare advection update of this flux from the current state
            kernels = scheme_stepper(eq.kernels, *eq.scheme.codes, False,
                                     L.GEOMETRY_PLANAR).ready()
            P = eq.parameter_array()
            *_, ok, _, _, _ = advect_step_function(1, False)(
                kernels.advect, kernels.sources, None, q, 0.0, T_FAR, 1.0 / 3,
                np.zeros((L.N_METRIC, n + 1)), *eq.bc_codes, P, *eq.kernels.constants(P), 0.5,
                diag, np.zeros_like(q), q.copy(), np.zeros((2, *q.shape)),
                np.zeros((1, L.N_DIAG)), np.zeros_like(q), np.zeros(L.N_DIAG), np.zeros(n),
                True, 0, n - 1, 0, n - 1, 0.0, n)
            if not ok:
                assert flux == "ifcp"  # only IFCP is not positive
            t = stepper(state, t, T_FAR)
            assert np.all(state.data[0] >= 0)
        fallbacks = solver.diagnostics[L.D_FLUX_FALLBACKS]
        assert (fallbacks > 0) if flux == "ifcp" else (fallbacks == 0)


def test_muscl_heap_below_friction_angle_stays_at_rest():
    """Found by test_states_at_rest_stay_at_rest (long profile)."""
    h = np.array([0.03200936, 0.02429672, 0.00891836, 0.0, 0.01049522, 0.02432341])
    check_single_layer_heap_stays_at_rest(h, "muscl")


# --- extremes: fast forms ----------------------------------------------------------------

def column(n: int, length: float, L0: float, H0: float, *, two_layer: bool = True,
           bc=("wall", "open"), x0: float = 0.0, **params):
    """A granular column of length L0 [m] and height H0 [m] from x0 [m] (for two
    layers a Rankine wedge of 60 deg under the upper layer, as in the paper)."""
    g = CartesianGrid([[0.0, length]], n)
    x = g.axes_coords[0]
    inside = (x >= x0) & (x < x0 + L0)
    if not two_layer:
        eq = pdeflow.SingleLayerGranular(bc=bc, **params)
        return eq, eq.make_state(g, h=np.where(inside, H0, 0.0))
    eq = pdeflow.TwoLayerGranular(bc=bc, **params)
    h2 = np.where(inside, np.minimum(H0, (x0 + L0 - x) * math.tan(math.radians(60))), 0.0)
    return eq, eq.make_state(g, h1=np.where(inside, H0 - h2, 0.0), h2=h2)


def run_to_rest(eq, state, t_end: float, cfl: float = 0.3):
    """fv-split run that ends at rest or at t_end; returns (state, info)."""
    return eq.solve(state, t_range=t_end, solver="fv-split", cfl=cfl, tracker=None,
                    ret_info=True)


@pytest.mark.parametrize("two_layer", [True, False])
@pytest.mark.parametrize("aspect, n, length, L0", [
    (100.0, 1500, 30.0, 0.1),  # tall column H0 = 10 m on 5 cells (run-out 12-23 m)
    (0.01, 200, 4.0, 2.0),    # flat slab H0 = 2 cm on 100 cells
])
def test_extreme_aspect_ratios_collapse_and_stop(aspect, n, length, L0, two_layer):
    eq, st0 = column(n, length, L0, aspect * L0, two_layer=two_layer, bc=("wall", "wall"))
    final, info = run_to_rest(eq, st0, 30.0)
    q = final.data
    assert info["solver"].get("rest_time") is not None  # came to rest by itself
    assert np.all(np.isfinite(q)) and np.all(q[::2] >= 0) and np.all(q[1::2] == 0)
    m0 = total_mass(eq, st0.data)
    assert abs(total_mass(eq, q) - m0) <= 1e-12 * m0
    H = q[0] + q[2] if two_layer else q[0]
    assert H.max() <= aspect * L0 * (1 + 1e-12)
    assert H[-1] == 0.0  # stayed inside the domain
    if aspect > 1:
        assert H.max() < 0.5 * aspect * L0  # the tall column really collapsed


def test_deposit_left_for_100_seconds_does_not_creep():
    eq, st0 = column(140, 7.0, 1.0, 2.0, bc=("wall", "wall"))  # test 5.1
    rest, info = run_to_rest(eq, st0, 10.0)
    t_rest = info["solver"]["rest_time"]
    assert 1.0 < t_rest < 2.0
    stepper = FVSplitSolver(eq, cfl=0.3, stop_at_rest=False).make_stepper(rest)
    later = rest.copy()
    t = stepper(later, t_rest, t_rest + 100.0)
    assert t == pytest.approx(t_rest + 100.0)
    np.testing.assert_array_equal(later.data, rest.data)


def run_uniform_layer_on_slope(two_layer: bool, theta: float, phi_b: float,
                               t_end: float):
    """A layer covering the whole bed (open ends: an infinite layer) on a slope."""
    g = CartesianGrid([[0.0, 1.0]], 20)
    if two_layer:
        eq = pdeflow.TwoLayerGranular(bc=("open", "open"), theta_deg=theta,
                                      phi_b_deg=phi_b)
        st0 = eq.make_state(g, h1=np.zeros(20), h2=np.full(20, 0.3))
    else:
        eq = pdeflow.SingleLayerGranular(bc=("open", "open"), theta_deg=theta,
                                         phi_b_deg=phi_b)
        st0 = eq.make_state(g, h=np.full(20, 0.3))
    stepper = FVSplitSolver(eq, cfl=0.5, stop_at_rest=False).make_stepper(st0)
    q = st0.copy()
    t = stepper(q, 0.0, t_end)
    return st0, q, t


@pytest.mark.parametrize("two_layer", [True, False])
def test_layer_just_below_the_friction_angle_stays_at_rest(two_layer):
    st0, q, t = run_uniform_layer_on_slope(two_layer, 40.9, 41.0, 5.0)
    np.testing.assert_array_equal(q.data, st0.data)


@pytest.mark.parametrize("two_layer", [True, False])
def test_layer_just_above_the_friction_angle_slides_with_the_coulomb_acceleration(
        two_layer):
    theta, phi = 41.1, 41.0
    st0, q, t = run_uniform_layer_on_slope(two_layer, theta, phi, 5.0)
    a = 9.81 * (math.sin(math.radians(theta))
                - math.cos(math.radians(theta)) * math.tan(math.radians(phi)))
    k = 3 if two_layer else 1
    u = q.data[k] / q.data[k - 1]
    np.testing.assert_allclose(u, a * t, rtol=1e-9)  # uniform acceleration, exactly
    np.testing.assert_array_equal(q.data[k - 1], st0.data[k - 1])


def check_column_on_slope(n: int, dtheta: float) -> None:
    """Column 1 m x 0.5 m on a slope 1 deg below / above phi_B = 30 deg, 50 m of bed
    (walls): below, it spreads (for ~30 m: the deceleration is only 0.2 m/s^2) and stops
    inside the domain; above, it is still sliding after 10 s."""
    phi = 30.0
    eq, st0 = column(n, 50.0, 1.0, 0.5, two_layer=False, bc=("wall", "wall"), x0=1.0,
                     theta_deg=phi + dtheta, phi_b_deg=phi)
    final, info = run_to_rest(eq, st0, 40.0 if dtheta < 0 else 10.0)
    q = final.data
    x = final.grid.axes_coords[0]
    assert np.all(np.isfinite(q)) and np.all(q[0] >= 0)
    assert abs(q[0].sum() - st0.data[0].sum()) <= 1e-12 * st0.data[0].sum()
    assert q[0][-1] == 0.0  # never reached the far wall
    at_rest = info["solver"].get("rest_time") is not None
    if dtheta < 0:
        assert at_rest and np.all(q[1] == 0)
    else:
        assert not at_rest and np.sum(q[1]) > 0
        assert np.sum(x * q[0]) > np.sum(x * st0.data[0]) + 5.0 * np.sum(q[0])


@pytest.mark.parametrize("dtheta", [-1.0, 1.0])
def test_column_on_a_slope_below_stops_and_above_keeps_sliding(dtheta):
    check_column_on_slope(500, dtheta)


def test_1e5_cells_short_run():
    """10^5 cells: 200 steps of the 5.1 column (heavy form: slow test; its wall time is
    measured by benchmarks/suite.py:large_grid_steps, docs/performance.md)."""
    eq, st0 = column(100_000, 7.0, 1.0, 2.0, bc=("wall", "wall"))
    stepper = FVSplitSolver(eq, cfl=0.3, stop_at_rest=False,
                            max_steps=200).make_stepper(st0)
    q = st0.copy()
    t = stepper(q, 0.0, 1.0)
    assert t > 0 and np.all(np.isfinite(q.data)) and np.all(q.data[::2] >= 0)
    m0 = total_mass(eq, st0.data)
    assert abs(total_mass(eq, q.data) - m0) <= 200 * 16 * EPS * m0


# --- extremes: heavy forms (slow) ------------------------------------------------------------

@pytest.mark.slow
def test_1e5_cells_first_tenth_of_a_second():
    """10^5 cells (dx = 7e-5 m) for the first 0.1 s of test 5.1 (~9000 steps; the run to
    rest takes 6.4e5 steps and half an hour, docs/stability.md)."""
    eq, st0 = column(100_000, 7.0, 1.0, 2.0, bc=("wall", "wall"))
    final, info = run_to_rest(eq, st0, 0.1)
    q = final.data
    assert np.all(np.isfinite(q)) and np.all(q[::2] >= 0)
    m0 = total_mass(eq, st0.data)
    assert abs(total_mass(eq, q) - m0) <= 1e-12 * m0
    x = final.grid.axes_coords[0]
    front = x[np.nonzero(q[0] + q[2] > 1e-3)[0][-1]]
    assert 1.5 < front < 2.0  # 1.75 m at dx = 0.05 m (docs/parameters.md)


@pytest.mark.slow
@pytest.mark.parametrize("two_layer", [True, False])
def test_aspect_ratio_100_fine_grid(two_layer):
    eq, st0 = column(20000, 40.0, 0.1, 10.0, two_layer=two_layer, bc=("wall", "wall"))
    final, info = run_to_rest(eq, st0, 30.0)
    q = final.data
    assert info["solver"].get("rest_time") is not None
    assert q[0][-1] == 0.0 and q[-2][-1] == 0.0  # stopped before the far wall
    assert np.all(np.isfinite(q)) and np.all(q[::2] >= 0)
    m0 = total_mass(eq, st0.data)
    assert abs(total_mass(eq, q) - m0) <= 1e-11 * m0


@pytest.mark.slow
@pytest.mark.parametrize("dtheta", [-1.0, 1.0])
def test_column_on_a_slope_fine_grid(dtheta):
    check_column_on_slope(2500, dtheta)


# --- the stability tool (pdeflow.analysis.stability) --------------------------------------------

def test_post_step_hook_counts_what_it_clips():
    """A generic solver's only check: the model's hook counts a step that left a depth
    below -1e-12 m or a non-finite value, before it clips the depth to 0."""
    eq = pdeflow.TwoLayerGranular(bc=("wall", "wall"))
    state = eq.make_state(CartesianGrid([[0.0, 1.0]], 4), h1=np.full(4, 0.5),
                          h2=np.full(4, 0.5))
    hook, diag = eq.make_post_step_hook(state)
    for value, bad in ((-1e-13, 0), (-1e-9, 1), (math.nan, 2), (0.1, 2)):
        q = state.data.copy()
        q[2, 1] = value
        hook(q, 0.0, diag)
        assert diag[L.D_BAD_STEPS] == bad
        assert q[2, 1] == max(value, 0.0) or math.isnan(value)


def test_stability_tool_classifies_runs():
    from pdeflow.analysis import stability as S
    from pdeflow.analysis.stability_problems import dam_break, shear, shear_band

    # the model's own Kelvin-Helmholtz instability: grows without correction only
    inside = shear(0.67, 1.0)
    assert shear_band(0.67)[0] < 1.0 * math.sqrt(9.81) < shear_band(0.67)[1]
    assert S.run("hll/first-order@none", inside, 0.3).status == "growth"
    assert S.run("hll/first-order", inside, 0.3).status == "stable"
    # beyond the CFL limit the paper's scheme blows up (the validation is bypassed)
    out = S.run("hll/first-order", dam_break(), 1.5)
    assert out.status == "blow-up" and "rejected" in out.detail
    # stiff regularised sources: explicit Euler on 5.1 needs a tiny CFL number; py-pde's
    # solver runs on, the hook's count (the depths it clipped) makes it a blow-up
    out = S.run("mol-euler", dam_break(), 0.3)
    assert out.status == "blow-up" and "negative depth" in out.detail


def test_stability_tool_writes_its_sections_and_keeps_the_rest(tmp_path):
    import importlib.util

    path = Path(__file__).resolve().parents[1] / "docs" / "generate" / "stability.py"
    spec = importlib.util.spec_from_file_location("generate_stability", path)
    gen = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(gen)
    md = tmp_path / "stability.md"
    md.write_text("# Stability\n\nhand-written text\n")
    assert gen.main(["--out", str(tmp_path), "--quick",
                     "--variants", "hll/first-order,hll/first-order@none"]) == 0
    text = md.read_text()
    assert text.startswith("# Stability\n\nhand-written text\n")
    assert text.count("<!-- BEGIN stability:map") == 1
    assert "| `hll/first-order` |" in text and "| `hll/first-order@none` |" in text
    for png in ("stability_map.png", "stability_cfl.png"):
        assert (tmp_path / png).stat().st_size > 10_000
    again = gen.replace_section(text, "map", "new content")
    assert again.count("<!-- BEGIN stability:map") == 1 and "new content" in again
    assert "hand-written text" in again
