"""AvaFrame's idealised topographies as beds z(x, y) [m], written from the equations its
``generateTopo`` module documents (AvaFrame, in3Utils), with its default parameters
(``generateTopoCfg.ini``) as the defaults here.

Coordinates are AvaFrame's for each: x [m] runs down the slope from the top (x = 0),
y [m] across, 0 on the path's axis; the bowl, helix and pyramid are centred at the
origin. Angles are in degrees. AvaFrame's options that superimpose a channel, a dam or
a drop, and its triple parabola, are not built here.

* :func:`inclined_plane`: z = z0 - tan(alpha) x;
* :func:`parabola`: z = C (1 - x / f)^2 for x < f, 0 beyond, with the foot f =
  C / tan(alpha): alpha is the *mean* slope from the top to the foot, the slope at the
  top is arctan(2 tan(alpha)), the run-out beyond the foot is flat;
* :func:`hockey_stick`: the plane z0 - tan(alpha) x down to the flat z = 0, the bend
  rounded by a circle of radius r_circ tangent to both (the plane alone would reach 0
  at x1 = z0 / tan(alpha); the arc spans x1 - r tan(alpha/2) cos(alpha) to x1 +
  r tan(alpha/2));
* :func:`bowl`: a spherical bowl of radius r_bowl, z = r - sqrt(r^2 - rho^2) for rho =
  sqrt(x^2 + y^2) <= r, the rim's height r beyond;
* :func:`helix`: the parabola's profile along the angle around the origin, s =
  r_helix * theta with theta = atan2(y, x) + pi in [0, 2 pi) (the top at theta = 0,
  on the negative x axis, turning through y < 0, AvaFrame's half-plane of the helix);
* :func:`pyramid`: a square pyramid of height z0 whose four faces slope at alpha,
  z = max(z0 - tan(alpha) max(|u|, |v|), 0) with (u, v) the point turned by -phi about
  the apex (the pyramid turned by phi about the vertical; flat foreland at 0).
"""

from __future__ import annotations

import math

import numpy as np

from ..models.base import check_range

MEAN_ALPHA_DEG = 34.0
"""AvaFrame's default slope angle [deg] (meanAlpha)"""
FALL_HEIGHT = 1000.0
"""AvaFrame's default fall height of the parabola and the helix [m] (C)"""
Z0 = 2200.0
"""AvaFrame's default top elevation of the plane, the hockey stick and the pyramid [m]"""


def _angle(mean_alpha_deg: float) -> float:
    """tan(alpha) of a slope angle checked in (0, 90) degrees."""
    check_range("mean_alpha_deg", mean_alpha_deg, 0, 90, low_open=True, high_open=True,
                unit="deg")
    return math.tan(math.radians(mean_alpha_deg))


def _positive(name: str, value: float) -> float:
    return check_range(name, value, 0, math.inf, low_open=True, high_open=True, unit="m")


def inclined_plane(x: np.ndarray, y: np.ndarray, z0: float = Z0,
                   mean_alpha_deg: float = MEAN_ALPHA_DEG) -> np.ndarray:
    """The plane z = z0 - tan(alpha) x [m] at the points ``x``, ``y`` [m]: top
    elevation ``z0`` [m] at x = 0, slope ``mean_alpha_deg`` [deg] down x."""
    check_range("z0", z0, -math.inf, math.inf, unit="m")
    return z0 - _angle(mean_alpha_deg) * np.asarray(x, float) + 0.0 * np.asarray(y, float)


def parabola_profile(s: np.ndarray, fall_height: float, mean_alpha_deg: float) -> np.ndarray:
    """z(s) = C (1 - s / f)^2 for s < f, 0 beyond, f = C / tan(alpha) [m]: the
    parabolic slope of fall height C [m] and mean slope alpha, flat from its foot on."""
    C = _positive("fall_height", fall_height)  # noqa: N806  AvaFrame's name
    foot = C / _angle(mean_alpha_deg)
    s = np.asarray(s, dtype=float)
    return np.where(s < foot, C * (1.0 - s / foot) ** 2, 0.0)


def parabola(x: np.ndarray, y: np.ndarray, fall_height: float = FALL_HEIGHT,
             mean_alpha_deg: float = MEAN_ALPHA_DEG) -> np.ndarray:
    """The parabolic slope with a flat run-out [m] at ``x``, ``y`` [m]: the top at x = 0
    at ``fall_height`` [m] above the flat, ``mean_alpha_deg`` [deg] the mean slope from
    the top to the foot (module docstring)."""
    return parabola_profile(x, fall_height, mean_alpha_deg) + 0.0 * np.asarray(y, float)


def hockey_stick(x: np.ndarray, y: np.ndarray, z0: float = Z0,
                 mean_alpha_deg: float = MEAN_ALPHA_DEG, r_circ: float = 200.0) -> np.ndarray:
    """The plane of slope ``mean_alpha_deg`` [deg] from ``z0`` [m] at x = 0 down to
    the flat z = 0, the bend a circle of radius ``r_circ`` [m] tangent to both
    (module docstring), at ``x``, ``y`` [m]."""
    z0 = _positive("z0", z0)
    r = _positive("r_circ", r_circ)
    tan_a = _angle(mean_alpha_deg)
    alpha = math.atan(tan_a)
    x1 = z0 / tan_a
    x_flat = x1 + r * math.tan(0.5 * alpha)  # the circle's lowest point, its centre above
    x_plane = x_flat - r * math.sin(alpha)  # where the circle touches the plane
    if x_plane < 0:
        r_max = x1 / (math.tan(0.5 * alpha) * math.cos(alpha))
        raise ValueError(f"r_circ must lie in (0, {r_max:g}] m for z0 = {z0:g} m and "
                         f"mean_alpha_deg = {mean_alpha_deg:g} (a larger bend would start "
                         f"above the top), got {r_circ!r}")
    x = np.asarray(x, dtype=float)
    arc = r - np.sqrt(np.maximum(r**2 - (x - x_flat) ** 2, 0.0))
    z = np.where(x < x_plane, z0 - tan_a * x, np.where(x < x_flat, arc, 0.0))
    return z + 0.0 * np.asarray(y, float)


def bowl(x: np.ndarray, y: np.ndarray, r_bowl: float = 500.0) -> np.ndarray:
    """The spherical bowl of radius ``r_bowl`` [m] centred at the origin, its bottom at
    z = 0 and its rim at z = r_bowl [m], flat beyond, at ``x``, ``y`` [m]."""
    r = _positive("r_bowl", r_bowl)
    rho2 = np.asarray(x, float) ** 2 + np.asarray(y, float) ** 2
    return np.where(rho2 <= r**2, r - np.sqrt(np.maximum(r**2 - rho2, 0.0)), r)


def helix(x: np.ndarray, y: np.ndarray, fall_height: float = FALL_HEIGHT,
          mean_alpha_deg: float = MEAN_ALPHA_DEG, r_helix: float = 1250.0) -> np.ndarray:
    """The parabolic profile (:func:`parabola_profile`) wound around the origin at
    ``x``, ``y`` [m]: at the angle theta in [0, 2 pi) from the negative x axis through
    y < 0, the elevation of the parabola at the arc length s = ``r_helix`` theta [m]."""
    r = _positive("r_helix", r_helix)
    theta = np.mod(np.arctan2(np.asarray(y, float), np.asarray(x, float)) + np.pi,
                   2.0 * np.pi)
    return parabola_profile(r * theta, fall_height, mean_alpha_deg)


def pyramid(x: np.ndarray, y: np.ndarray, z0: float = Z0,
            mean_alpha_deg: float = MEAN_ALPHA_DEG, phi_deg: float = 25.0) -> np.ndarray:
    """The square pyramid of height ``z0`` [m] with its apex at the origin, faces of
    slope ``mean_alpha_deg`` [deg], turned by ``phi_deg`` [deg] about the vertical
    (AvaFrame's default turns it by 25 deg), on a flat foreland z = 0, at ``x``, ``y``
    [m]."""
    z0 = _positive("z0", z0)
    tan_a = _angle(mean_alpha_deg)
    phi = math.radians(check_range("phi_deg", phi_deg, -360, 360, unit="deg"))
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    u = math.cos(phi) * x + math.sin(phi) * y
    v = -math.sin(phi) * x + math.cos(phi) * y
    return np.maximum(z0 - tan_a * np.maximum(np.abs(u), np.abs(v)), 0.0)


TOPOGRAPHIES = {"inclined_plane": inclined_plane, "parabola": parabola,
                "hockey_stick": hockey_stick, "bowl": bowl, "helix": helix,
                "pyramid": pyramid}
"""AvaFrame's idealised topographies by name (its IP, PF, HS, BL, HX, PY)"""
