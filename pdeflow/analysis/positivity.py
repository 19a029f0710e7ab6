"""Positivity stress: random two- and one-layer states of every fv-split variant.

Each state is drawn like the two regression states (``tests/data/
positivity_state_*``): a small walled grid, thin upper films (1e-7 to 1e-4 m) next to
thicker upper layers over a stepped lower layer that is often at rest, random
parameters, any flux, reconstruction, limiter, splitting and hyperbolicity mode, and a
CFL number anywhere in the range the case validation accepts ((0, 1], (0, 0.5] with
MUSCL). A run counts as a failure if it raises :class:`SimulationBlowUp` or ends with a
negative depth; the steps the solver rejected and retried with a smaller dt (the
positivity safety net) are counted. ``docs/generate/positivity.py`` runs 10^4 of them
for docs/stability.md; ``tests/test_positivity.py`` a few in the default suite.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from pde import CartesianGrid

from .. import systems
from ..cases import BASELINE_MODEL, PAPER_MODEL
from ..metrics import mass
from ..numerics import layout as L
from ..solvers.fv_split import SimulationBlowUp
from ..variant import HYPERBOLICITY

FLUXES = tuple(L.FLUXES)  # the shipped fluxes: read once, so draws stay reproducible
SCHEMES = (("first-order", "minmod"), ("muscl", "minmod"), ("muscl", "mc"))
MODES = HYPERBOLICITY


@dataclass
class StressState:
    """One drawn state: model, parameters, scheme, CFL number and profiles."""

    model: str
    """the registered name of the model"""
    params: dict[str, Any]
    scheme: dict[str, str]
    splitting: str
    cfl: float
    profiles: dict[str, np.ndarray] = field(repr=False)
    length: float = 1.0

    @property
    def variant(self) -> str:
        """e.g. ``two/hll/muscl/mc/strang`` (the stress figure's groups)."""
        s = self.scheme
        rec = s["reconstruction"] + ("/" + s["limiter"] if s["reconstruction"] == "muscl"
                                     else "")
        layers = len(systems.get(self.model).layers)
        return f"{'two' if layers == 2 else 'one'}/{s['flux']}/{rec}/{self.splitting}"


@dataclass
class StressResult:
    """Outcome of one run: ``blowup`` (the message, or None), the steps rejected and
    retried, the smallest depth of the final state [m], the relative mass error."""

    variant: str
    blowup: str | None
    retries: int
    min_depth: float
    mass_error: float
    steps: int


def _profile(rng: np.random.Generator, n: int) -> dict[str, np.ndarray]:
    """Two-layer profiles [m, m/s]: a stepped lower layer, at rest in half the draws,
    under an upper layer that is thick in some cells and a thin film in others."""
    h2 = np.repeat(rng.uniform(0.0, 0.5, n // 3 + 1), 3)[:n] * (rng.random(n) > 0.1)
    h1 = np.where(rng.random(n) < 0.5, 10.0 ** rng.uniform(-7.0, -4.0, n),
                  rng.uniform(0.0, 0.05, n))
    h1[rng.random(n) < 0.15] = 0.0
    u1 = 10.0 ** rng.uniform(-2.0, 0.5) * rng.standard_normal(n)
    u2 = (0.0 if rng.random() < 0.5 else 10.0 ** rng.uniform(-2.0, 0.0)) * \
        rng.standard_normal(n)
    return {"h1": h1, "u1": u1, "h2": h2, "u2": u2}


def draw_state(rng: np.random.Generator) -> StressState:
    """A random state (3 in 4 two-layer) of a random variant; see the module docstring."""
    two = rng.random() < 0.75
    n = int(rng.integers(8, 48))
    rec, limiter = SCHEMES[int(rng.integers(len(SCHEMES)))]
    scheme = {"flux": FLUXES[int(rng.integers(len(FLUXES)))], "reconstruction": rec,
              "limiter": limiter}
    splitting = "strang" if rng.random() < 0.5 else "lie"
    cfl = float(rng.uniform(0.05, 0.5 if rec == "muscl" else 1.0))
    phi_b = float(rng.uniform(15.0, 55.0))
    params: dict[str, Any] = {"phi_b_deg": phi_b,
                              "theta_deg": float(rng.uniform(-20.0, 20.0))}
    profiles = _profile(rng, n)
    if two:
        params.update(density_ratio=float(rng.uniform(0.3, 0.95)),
                      phi_int_deg=float(rng.uniform(20.0, 40.0)),
                      k=float(rng.uniform(0.1, 0.99)), c=float(10.0 ** rng.uniform(-3, 0.5)),
                      hyperbolicity=MODES[int(rng.integers(len(MODES)))],
                      exchange_closure=("paper", "relaxed", "none")[int(rng.integers(3))])
    else:
        profiles = {"h": profiles["h1"] + profiles["h2"], "u": profiles["u1"]}
    return StressState(PAPER_MODEL if two else BASELINE_MODEL, params, scheme, splitting,
                       cfl, profiles)


def run_state(s: StressState, t_end: float = 0.1) -> StressResult:
    """Run ``s`` with fv-split (walls at both ends) to rest or ``t_end`` [s]."""
    n = next(iter(s.profiles.values())).size
    eq = systems.get(s.model).pde_class(bc=("wall", "wall"), **s.scheme, **s.params)
    state = eq.make_state(CartesianGrid([[0.0, s.length]], n), **s.profiles)
    r = eq.system.densities(eq.parameters)
    dx = s.length / n
    m0 = mass(state.data, dx, r)
    blowup = None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            final, info = eq.solve(state, t_range=t_end, solver="fv-split", cfl=s.cfl,
                                   splitting=s.splitting, tracker=None, ret_info=True)
        except SimulationBlowUp as err:
            blowup = str(err)
            final, info = state, {"solver": {"steps": err.step or 0}}
    data = info["solver"].get("post_step_data")
    retries = int(data[L.D_RETRIES]) if isinstance(data, np.ndarray) else 0
    q = final.data
    return StressResult(s.variant, blowup, retries, float(np.min(q[::2])),
                        abs(mass(q, dx, r) - m0) / m0 if m0 else 0.0,
                        int(info["solver"].get("steps", 0)))


def stress(count: int, seed: int, t_end: float = 0.1) -> list[StressResult]:
    """``count`` random states from ``numpy.random.default_rng(seed)``, each run."""
    rng = np.random.default_rng(seed)
    return [run_state(draw_state(rng), t_end) for _ in range(count)]


def tally(results: list[StressResult]) -> dict[str, dict[str, float]]:
    """Per variant: runs, blow-ups, negative final depths, runs with retried steps,
    retried steps, largest mass error."""
    out: dict[str, dict[str, float]] = {}
    for res in results:
        row = out.setdefault(res.variant, {"runs": 0, "blow-ups": 0, "negative": 0,
                                           "retried runs": 0, "retried steps": 0,
                                           "max mass error": 0.0})
        row["runs"] += 1
        row["blow-ups"] += res.blowup is not None
        row["negative"] += res.min_depth < 0
        row["retried runs"] += res.retries > 0
        row["retried steps"] += res.retries
        row["max mass error"] = max(row["max mass error"], res.mass_error)
    return dict(sorted(out.items()))
