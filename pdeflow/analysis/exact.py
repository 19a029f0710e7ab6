"""Exact solutions used to verify the schemes, their formulas restated here: Ritter's
frictionless dam break (Ritter 1892, Die Fortpflanzung der
Wasserwellen, Z. Ver. Dtsch. Ing. 36, 947-954) and its extension to a
slope with Coulomb friction (Mangeney, Heinrich & Roche 2000, Analytical solution for
testing debris avalanche numerical models, Pure Appl. Geophys. 157, 1081-1096)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import systems
from ..cases import BASELINE_MODEL


def ritter(x: np.ndarray, t: float, h0: float, x0: float = 0.0,
           g: float = 9.81) -> tuple[np.ndarray, np.ndarray]:
    """Ritter's frictionless dam break onto a dry bed.

    Reservoir of depth h0 [m] for x < x0 at t = 0, c0 = sqrt(g h0). For
    x0 - c0 t <= x <= x0 + 2 c0 t: h = (2 c0 - (x - x0)/t)^2 / (9 g),
    u = 2/3 ((x - x0)/t + c0); h = h0, u = 0 upstream and h = 0 downstream.
    Returns (h [m], u [m/s]) at the points x [m].
    """
    return mangeney(x, t, h0, x0=x0, g=g, theta_deg=0.0, delta_deg=0.0)


def mangeney(x: np.ndarray, t: float, h0: float, x0: float = 0.0, g: float = 9.81,
             theta_deg: float = 0.0, delta_deg: float = 0.0
             ) -> tuple[np.ndarray, np.ndarray]:
    """Mangeney, Heinrich & Roche (2000): dam break on a slope theta with Coulomb
    friction angle delta <= theta (h normal to the bed, x down-slope).

    m = g cos(theta)(tan(theta) - tan(delta)), c0 = sqrt(g cos(theta) h0);
    rear x_A = x0 - c0 t + m t^2/2, front x_B = x0 + 2 c0 t + m t^2/2.
    x <= x_A: h = h0, u = m t; x_A < x <= x_B: h = (2 c0 - (x - x0)/t + m t/2)^2 /
    (9 g cos theta), u = 2/3 ((x - x0)/t + c0 + m t); beyond x_B: h = 0.
    """
    th = math.radians(theta_deg)
    gz = g * math.cos(th)
    m = gz * (math.tan(th) - math.tan(math.radians(delta_deg)))
    c0 = math.sqrt(gz * h0)
    x = np.asarray(x, dtype=float)
    if t <= 0:
        return np.where(x < x0, h0, 0.0), np.zeros_like(x)
    xa = x0 - c0 * t + 0.5 * m * t * t
    xb = x0 + 2 * c0 * t + 0.5 * m * t * t
    xi = (x - x0) / t
    h_fan = (2 * c0 - xi + 0.5 * m * t) ** 2 / (9 * gz)
    u_fan = 2.0 / 3.0 * (xi + c0 + m * t)
    h = np.where(x <= xa, h0, np.where(x <= xb, h_fan, 0.0))
    u = np.where(x <= xa, m * t, np.where(x <= xb, u_fan, 0.0))
    return h, u


def stoker(x: np.ndarray, t: float, h_left: float, h_right: float, x0: float = 0.0,
           g: float = 9.81) -> tuple[np.ndarray, np.ndarray]:
    """Stoker's frictionless dam break onto a wet bed (h_right > 0).

    The middle state (h_m, u_m) solves 2 (c_l - c_m) = (h_m - h_r) sqrt(g (h_m + h_r) /
    (2 h_m h_r)) (rarefaction meets shock); the shock moves at S = h_m u_m / (h_m - h_r).
    Regions: reservoir; rarefaction fan x0 - c_l t .. x0 + (u_m - c_m) t with
    h = (2 c_l - xi)^2 / (9 g), u = 2/3 (xi + c_l); middle state up to x0 + S t;
    undisturbed h_r beyond. Returns (h [m], u [m/s]).
    """
    from scipy.optimize import brentq

    if h_right <= 0:
        return ritter(x, t, h_left, x0=x0, g=g)
    cl = math.sqrt(g * h_left)

    def f(hm: float) -> float:
        return (2 * (cl - math.sqrt(g * hm))
                - (hm - h_right) * math.sqrt(g * (hm + h_right) / (2 * hm * h_right)))

    hm = brentq(f, h_right, h_left)
    cm = math.sqrt(g * hm)
    um = 2 * (cl - cm)
    s = hm * um / (hm - h_right)
    x = np.asarray(x, dtype=float)
    if t <= 0:
        return np.where(x < x0, h_left, h_right), np.zeros_like(x)
    xi = (x - x0) / t
    h = np.where(xi <= -cl, h_left,
                 np.where(xi <= um - cm, (2 * cl - xi) ** 2 / (9 * g),
                          np.where(xi <= s, hm, h_right)))
    u = np.where(xi <= -cl, 0.0,
                 np.where(xi <= um - cm, 2.0 / 3.0 * (xi + cl),
                          np.where(xi <= s, um, 0.0)))
    return h, u


FRICTIONLESS_DEG = 1e-6
"""Friction angles at or below this [deg] count as zero: case files write a frictionless
bed as phi_b_deg = 1e-9 (angles must lie in (0, 90) deg)."""


@dataclass(frozen=True)
class ExactSolution:
    """A single-layer dam break with an exact solution (Ritter, Mangeney, Stoker).

    Depth ``h_left`` [m] upstream of the dam at ``x0`` [m], ``h_right`` [m] downstream
    (> 0: Stoker, flat frictionless bed only), bed slope ``theta_deg`` and Coulomb
    friction ``delta_deg`` <= theta (Mangeney; Ritter for both 0).
    """

    name: str
    h_left: float
    h_right: float
    x0: float
    g: float = 9.81
    theta_deg: float = 0.0
    delta_deg: float = 0.0

    def __call__(self, x: np.ndarray, t: float) -> tuple[np.ndarray, np.ndarray]:
        """(h [m], u [m/s]) at the points ``x`` [m] and time ``t`` [s]."""
        if self.h_right > 0:
            return stoker(x, t, self.h_left, self.h_right, x0=self.x0, g=self.g)
        return mangeney(x, t, self.h_left, x0=self.x0, g=self.g,
                        theta_deg=self.theta_deg, delta_deg=self.delta_deg)

    def front(self, t: float) -> float | None:
        """Position [m] of the dry front at ``t`` (None on a wet bed)."""
        if self.h_right > 0:
            return None
        th = math.radians(self.theta_deg)
        gz = self.g * math.cos(th)
        m = gz * (math.tan(th) - math.tan(math.radians(self.delta_deg)))
        return self.x0 + 2 * math.sqrt(gz * self.h_left) * t + 0.5 * m * t * t

    def cell_averages(self, edges: np.ndarray, t: float,
                      points: int = 8) -> tuple[np.ndarray, np.ndarray]:
        """Cell averages of (h [m], hu [m^2/s]) between ``edges`` [m] (midpoint rule
        with ``points`` points per cell)."""
        lo, hi = edges[:-1], edges[1:]
        frac = (np.arange(points) + 0.5) / points
        x = lo[:, None] + (hi - lo)[:, None] * frac[None, :]
        h, u = self(x, t)
        return h.mean(axis=1), (h * u).mean(axis=1)


def exact_solution_for(case: Any, model: str = BASELINE_MODEL) -> ExactSolution | None:
    """The exact solution of a case, or None if it has none.

    Dam breaks (``initial.shape = "dam_break"``) of a one-layer Saint-Venant model with
    Coulomb friction (``basal_friction_deg`` of its parameters; 0: frictionless):
    onto a dry bed with phi_B <= theta, Mangeney's solution (Ritter's for
    theta = phi_B = 0); onto a wet bed (``h_right > 0``) on a flat frictionless bed,
    Stoker's. Valid while the waves stay inside the domain, on the planar grid. A
    rate-dependent basal law (``friction_law`` other than Coulomb) has none of these.
    """
    ini = case.initial
    if (len(systems.get(model).layers) != 1 or ini.get("shape") != "dam_break"
            or case.geometry != "planar"):
        return None
    p = case.make_pde(model).parameters
    if getattr(p, "rate_dependent_law", False):
        return None
    phi_b = p.basal_friction_deg
    delta = phi_b if phi_b > FRICTIONLESS_DEG else 0.0
    h_right = float(ini.get("h_right", 0.0))
    x0 = case.x_start + float(ini["x_dam"])
    if h_right > 0:
        if p.theta_deg != 0.0 or delta != 0.0:
            return None
        return ExactSolution("stoker", float(ini["h_left"]), h_right, x0, p.g)
    if delta > max(p.theta_deg, 0.0) + 1e-6:
        return None
    name = "ritter" if p.theta_deg == 0.0 and delta == 0.0 else "mangeney"
    return ExactSolution(name, float(ini["h_left"]), 0.0, x0, p.g, p.theta_deg, delta)
