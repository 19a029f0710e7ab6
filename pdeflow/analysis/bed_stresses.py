r"""The stresses at an erodible bed under a two-layer flow, from the model's formulas.

Kinematic stresses (divided by rho2) [m^2/s^2] of a two-layer state (h1, u1, h2, u2 in
m and m/s per cell), as in :mod:`pdeflow.models.two_layer.exchange` (r = rho1/rho2, g_z = g
cos(theta), g_x = g sin(theta), du = u1 - u2):

* interface, upper side (22): :math:`t_1 = k\,r g_z h_1 \tan\varphi_{int} + c\,du^2`;
* interface, lower side (23): :math:`t_2 = r g_z h_1 \tan\varphi_{int}`;
* their difference drives the exchange (25): :math:`M/\rho_2 = (t_1 - t_2)/\max(|du|,
  du_{reg})`, i.e. the bed is eroded where :math:`c\,du^2 > (1-k)\,r g_z h_1
  \tan\varphi_{int}` (the *erosion criterion*, which holds whatever the slope);
* the basal Coulomb stress the bed can resist (15):
  :math:`t_B^{max} = g_z (r h_1 + h_2)\tan\varphi_B`;
* the driving stress on the lower layer at rest, from its momentum equation (24):
  :math:`g_x h_2 - g_z h_2\,\partial_x (h_2 + r h_1) + \mathrm{sgn}(du)\, t_2`
  (gravity along the slope, the hydrostatic pressure gradients, and the interface
  stress the lower layer receives).

The lower layer at rest fails as a whole (slides on the rigid bed) only where the
driving stress exceeds :math:`t_B^{max}`. Without the pressure gradients that needs
:math:`g_x h_2 + r g_z h_1\tan\varphi_{int} > g_z (r h_1 + h_2)\tan\varphi_B`, which is
impossible when theta < phi_B and phi_int <= phi_B: the shipped parameter sets' beds can
only be eroded from the top, by the exchange.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np


def bed_stresses(h1: np.ndarray, u1: np.ndarray, h2: np.ndarray, u2: np.ndarray,
                 dx: float, p: Any) -> dict[str, np.ndarray]:
    """The stresses of the module docstring per cell [m^2/s^2] (``p``: the
    :class:`~pdeflow.models.two_layer.TwoLayerParameters`; Coulomb basal friction only),
    with ``M`` = M/rho2 [m/s] (0 where h1 = 0) and ``erodes`` (the criterion holds where
    there is an upper layer and a bed to erode)."""
    if getattr(p, "friction_law", "coulomb") != "coulomb":
        raise ValueError(f"bed_stresses: friction_law must be 'coulomb', got "
                         f"{p.friction_law!r}")
    th = math.radians(p.theta_deg)
    gz, gx = p.g * math.cos(th), p.g * math.sin(th)
    r, tan_int = p.density_ratio, math.tan(math.radians(p.phi_int_deg))
    du = u1 - u2
    t1 = p.k * r * gz * h1 * tan_int + p.c * du**2
    t2 = r * gz * h1 * tan_int
    wet1 = h1 > p.dry_tolerance
    den = np.maximum(np.abs(du), p.du_reg)
    with np.errstate(divide="ignore", invalid="ignore"):
        M = np.where(wet1 & (den > 0), (t1 - t2) / np.where(den > 0, den, 1.0), 0.0)
    surface = np.gradient(h2 + r * h1, dx)
    drive = gx * h2 - gz * h2 * surface + np.sign(du) * t2
    return {"t1": t1, "t2": t2, "M": M, "t_b_max": gz * (r * h1 + h2) *
            math.tan(math.radians(p.phi_b_deg)), "drive": drive,
            "drive_no_pressure": gx * h2 + np.sign(du) * t2,
            "erodes": wet1 & (h2 > p.dry_tolerance) & (t1 > t2)}
