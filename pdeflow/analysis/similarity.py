"""The Savage-Hutter similarity solution: a parabolic cap of Coulomb material sliding and
spreading down an inclined plane (Hutter, Siegel, Savage & Nohguchi 1993, Two-dimensional
spreading of a granular avalanche down an inclined plane, Part I: theory, Acta Mech. 100,
37-68; AvaFrame uses it as its analytic test, ``ana1Tests/simiSolTest``).

Coordinates on the plane inclined at zeta: x along the slope (downwards), y across,
both [m] from the release's centre; h [m] normal to the plane. With g_z = g cos(zeta),
mu = tan(delta) (delta the basal friction angle) and s = g sin(zeta) - mu g_z > 0 the
net acceleration down the slope, the cap at time t [s] is

    h(x, y, t) = h_c(t) max(1 - ((x - x_c(t)) / a(t))^2 - (y / b(t))^2, 0),
    h_c = H L_x L_y / (a b)                        (its volume pi/2 H L_x L_y is kept),
    x_c = s t^2 / 2,                               (the centre slides at u_c = s t)
    a'' = 2 k_x g_z h_c / a,
    b'' = 2 k_y g_z h_c / b - mu g_z b' / u_c,

from a(0) = L_x, b(0) = L_y at rest (a' = b' = 0). The velocity is u = u_c + (x - x_c)
a'/a, v = y b'/b. The solution takes the basal friction along x as -mu g_z everywhere
and across as -mu g_z v / u_c, where the depth-averaged equations have -mu g_z u/|u|: it
is therefore not an exact solution of them, only close to one while u_c dominates the
spreading velocities. k_x, k_y are the earth-pressure coefficients (1: the hydrostatic
pressure of pdeflow's single layer; AvaFrame's test with ``flagEarth = False``).

At t = 0 the friction term across is 0/0; its limit is b'(t)/u_c -> b''(0)/s, so
b''(0) = 2 k_y g_z h_c / b * s / (g sin zeta) there. In AvaFrame's dimensionless
variables g = a/L_x, f = b/L_y and the time t / sqrt(L_x / g).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..models.base import check_range

G = 9.81  #: gravity [m/s^2]


@dataclass(frozen=True)
class CapSolution:
    """The similarity solution's ODE, solved once over [0, t_end] (dense output).

    Attributes: ``slope_deg`` zeta [deg], ``friction_deg`` delta [deg], ``L_x``,
    ``L_y`` the initial semi-axes along and across the slope [m], ``H`` the initial
    height [m], ``k_x``, ``k_y`` the earth-pressure coefficients [-], ``g`` [m/s^2].
    """

    slope_deg: float
    friction_deg: float
    L_x: float
    L_y: float
    H: float
    t_end: float
    k_x: float = 1.0
    k_y: float = 1.0
    g: float = G

    def __post_init__(self) -> None:
        check_range("slope_deg", self.slope_deg, 0.0, 90.0, low_open=True,
                    high_open=True, unit="deg")
        # below the slope, or the centre does not slide (s <= 0) and the ODE's friction
        # term across (over u_c) has no meaning
        check_range("friction_deg", self.friction_deg, 0.0, self.slope_deg,
                    low_open=True, high_open=True, unit="deg")
        units = {"t_end": "s", "g": "m/s^2", "k_x": "", "k_y": ""}
        for name in ("L_x", "L_y", "H", "t_end", "k_x", "k_y", "g"):
            check_range(name, getattr(self, name), 0.0, math.inf, low_open=True,
                        unit=units.get(name, "m"))
        object.__setattr__(self, "_dense", self._solve())

    @property
    def g_z(self) -> float:
        """Gravity normal to the plane [m/s^2]."""
        return self.g * math.cos(math.radians(self.slope_deg))

    @property
    def mu(self) -> float:
        """The Coulomb coefficient tan(delta) [-]."""
        return math.tan(math.radians(self.friction_deg))

    @property
    def s(self) -> float:
        """The centre's acceleration down the slope, g sin(zeta) - mu g_z [m/s^2]."""
        return self.g * math.sin(math.radians(self.slope_deg)) - self.mu * self.g_z

    def _rhs(self, t: float, q: np.ndarray) -> list[float]:
        """d/dt of (a, a', b, b') [m, m/s, m, m/s]: the module docstring's ODE."""
        a, da, b, db = q
        hc = self.H * self.L_x * self.L_y / (a * b)
        dda = 2.0 * self.k_x * self.g_z * hc / a
        spread = 2.0 * self.k_y * self.g_z * hc / b
        if t <= 0.0:  # the limit of b'/u_c at t = 0 (module docstring)
            ddb = spread * self.s / (self.g * math.sin(math.radians(self.slope_deg)))
        else:
            ddb = spread - self.mu * self.g_z * db / (self.s * t)
        return [da, dda, db, ddb]

    def _solve(self) -> object:
        from scipy.integrate import solve_ivp

        # tolerances far below the schemes' errors (1e-3 and up), so that the reference
        # adds nothing measurable to them
        sol = solve_ivp(self._rhs, (0.0, self.t_end), [self.L_x, 0.0, self.L_y, 0.0],
                        method="DOP853", rtol=1e-11, atol=1e-12, dense_output=True)
        if not sol.success:
            raise RuntimeError(f"the similarity ODE failed: {sol.message}")
        return sol.sol

    def state(self, t: float) -> dict[str, float]:
        """At time t [s]: the semi-axes ``a``, ``b`` [m] and their rates ``da``, ``db``
        [m/s], the height ``h_c`` [m], the centre ``x_c`` [m down the slope from the
        release's centre] and its speed ``u_c`` [m/s]; ``g``, ``f`` = a/L_x, b/L_y."""
        check_range("t", t, 0.0, self.t_end, unit="s")
        a, da, b, db = (float(v) for v in self._dense(t))
        return {"a": a, "da": da, "b": b, "db": db,
                "h_c": self.H * self.L_x * self.L_y / (a * b),
                "x_c": 0.5 * self.s * t * t, "u_c": self.s * t,
                "g": a / self.L_x, "f": b / self.L_y}

    def depth(self, x: np.ndarray, y: np.ndarray, t: float) -> np.ndarray:
        """Slope-normal thickness h [m] at the points (x, y) [m along and across the
        slope from the release's centre] at time t [s]."""
        st = self.state(t)
        rho2 = ((np.asarray(x) - st["x_c"]) / st["a"]) ** 2 + (np.asarray(y) / st["b"]) ** 2
        return st["h_c"] * np.maximum(1.0 - rho2, 0.0)

    @property
    def volume(self) -> float:
        """The cap's volume pi/2 H L_x L_y [m^3], the same at every time."""
        return 0.5 * math.pi * self.H * self.L_x * self.L_y
