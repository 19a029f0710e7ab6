r"""Speed-of-light baseline in 2D: a minimal hand-written numba loop of the same scheme.

The 2D twin of :mod:`baseline`: first-order single-layer HLL on a 2D grid (x: axis 0,
y: axis 1; faces of each axis in their normal frame, the tangential momentum carried
by the mass flux from upwind, the same at-rest rule at faces as pdeflow), forward Euler
with the CFL step over both axes (dt = cfl / (2 max(s_x / dx, s_y / dy))) recomputed
every step, and the implicit set-valued vector Coulomb friction (gravity along x
included) applied to the speed along the velocity. Walls or open sides per axis; ends at
rest (no mass moved and no momentum left). It visits only the bounding box of the wet
cells plus one cell, fuses the update with the friction and keeps no backup, no
diagnostics and no failure checks. It is not part of the package;
``benchmarks/two_d_cost.py`` checks that it reproduces pdeflow's ``hll/first-order``
single-layer 2D run.

Units: depths h [m], momenta hu, hv [m^2/s], dx, dy [m], times [s], g [m/s^2].
"""

from __future__ import annotations

import math

import numpy as np
from baseline import _fluct as fluct_1d
from numba import njit


@njit(cache=True, inline="always")
def _fluct(hL: float, mL: float, tL: float, hR: float, mR: float, tR: float, g: float,
           dry: float):
    """HLL fluctuations in a face's normal frame: (D^-_h, D^-_n, D^-_t, D^+_h, D^+_n,
    D^+_t, max |speed|) for the states (h, normal momentum, tangential momentum): the
    1D baseline's for (h, normal momentum), the tangential momentum carried by the
    mass flux from upwind."""
    dm0, dm1, dp0, dp1, smax = fluct_1d(hL, mL, hR, mR, g, dry)
    fL = mL / hL * hL if hL > dry else 0.0  # as pdeflow: velocity times depth
    fR = mR / hR * hR if hR > dry else 0.0
    vL = tL / hL if hL > dry else 0.0
    vR = tR / hR if hR > dry else 0.0
    mass = fL + dm0
    t_minus = mass * (vL if mass > 0.0 else vR) - fL * vL
    return dm0, dm1, t_minus, dp0, dp1, fR * vR - fL * vL - t_minus, smax


@njit(cache=True)
def _wet_box(h: np.ndarray, dry: float):
    """(i0, i1, j0, j1): the wet cells' bounding box; i0 > i1 if nothing is wet."""
    nx, ny = h.shape
    i0, i1, j0, j1 = nx, -1, ny, -1
    for i in range(nx):
        for j in range(ny):
            if h[i, j] > dry:
                i0 = min(i0, i)
                i1 = max(i1, i)
                j0 = min(j0, j)
                j1 = max(j1, j)
    return i0, i1, j0, j1


@njit(cache=True)
def run_to_rest(h: np.ndarray, m: np.ndarray, n: np.ndarray, dx: float, dy: float,
                t_end: float, g_z: float, g_x: float, tan_phi: float, cfl: float,
                walls: np.ndarray, dry: float = 1e-6):
    """Advance (h, hu = m, hv = n), arrays (nx, ny), in place until rest or ``t_end``;
    ``walls`` = (x low, x high, y low, y high) booleans (else open); returns
    (t [s], steps)."""
    nx, ny = h.shape
    rh = np.zeros((nx, ny))
    rm = np.zeros((nx, ny))
    rn = np.zeros((nx, ny))
    sx_lo = -1.0 if walls[0] else 1.0
    sx_hi = -1.0 if walls[1] else 1.0
    sy_lo = -1.0 if walls[2] else 1.0
    sy_hi = -1.0 if walls[3] else 1.0
    t = 0.0
    steps = 0
    mu = g_z * tan_phi
    while t < t_end:
        i0, i1, j0, j1 = _wet_box(h, dry)
        if i0 > i1:
            break
        a, b = max(i0 - 1, 0), min(i1 + 1, nx - 1)
        c, d = max(j0 - 1, 0), min(j1 + 1, ny - 1)
        rh[a:b + 1, c:d + 1] = 0.0
        rm[a:b + 1, c:d + 1] = 0.0
        rn[a:b + 1, c:d + 1] = 0.0
        sx = 0.0
        sy = 0.0
        for i in range(a, b + 1):
            for j in range(c, d + 1):
                # the x-face between (i - 1, j) and (i, j), if a cell beside it is wet
                if i > 0 and (h[i - 1, j] > dry or h[i, j] > dry):
                    dm0, dm1, dm2, dp0, dp1, dp2, s = _fluct(
                        h[i - 1, j], m[i - 1, j], n[i - 1, j], h[i, j], m[i, j], n[i, j],
                        g_z, dry)
                    sx = max(sx, s)
                    rh[i - 1, j] -= dm0
                    rm[i - 1, j] -= dm1
                    rn[i - 1, j] -= dm2
                    rh[i, j] -= dp0
                    rm[i, j] -= dp1
                    rn[i, j] -= dp2
                if j > 0 and (h[i, j - 1] > dry or h[i, j] > dry):  # the y-face
                    dm0, dm1, dm2, dp0, dp1, dp2, s = _fluct(
                        h[i, j - 1], n[i, j - 1], m[i, j - 1], h[i, j], n[i, j], m[i, j],
                        g_z, dry)
                    sy = max(sy, s)
                    rh[i, j - 1] -= dm0 * dx / dy
                    rn[i, j - 1] -= dm1 * dx / dy
                    rm[i, j - 1] -= dm2 * dx / dy
                    rh[i, j] -= dp0 * dx / dy
                    rn[i, j] -= dp1 * dx / dy
                    rm[i, j] -= dp2 * dx / dy
        # the sides' ghost faces (a wall mirrors the normal momentum)
        if a == 0:
            for j in range(c, d + 1):
                _, _, _, dp0, dp1, dp2, s = _fluct(h[0, j], sx_lo * m[0, j], n[0, j],
                                                   h[0, j], m[0, j], n[0, j], g_z, dry)
                sx = max(sx, s)
                rh[0, j] -= dp0
                rm[0, j] -= dp1
                rn[0, j] -= dp2
        if b == nx - 1:
            for j in range(c, d + 1):
                dm0, dm1, dm2, _, _, _, s = _fluct(h[b, j], m[b, j], n[b, j], h[b, j],
                                                   sx_hi * m[b, j], n[b, j], g_z, dry)
                sx = max(sx, s)
                rh[b, j] -= dm0
                rm[b, j] -= dm1
                rn[b, j] -= dm2
        if c == 0:
            for i in range(a, b + 1):
                _, _, _, dp0, dp1, dp2, s = _fluct(h[i, 0], sy_lo * n[i, 0], m[i, 0],
                                                   h[i, 0], n[i, 0], m[i, 0], g_z, dry)
                sy = max(sy, s)
                rh[i, 0] -= dp0 * dx / dy
                rn[i, 0] -= dp1 * dx / dy
                rm[i, 0] -= dp2 * dx / dy
        if d == ny - 1:
            for i in range(a, b + 1):
                dm0, dm1, dm2, _, _, _, s = _fluct(h[i, d], n[i, d], m[i, d], h[i, d],
                                                   sy_hi * n[i, d], m[i, d], g_z, dry)
                sy = max(sy, s)
                rh[i, d] -= dm0 * dx / dy
                rn[i, d] -= dm1 * dx / dy
                rm[i, d] -= dm2 * dx / dy
        dt = t_end - t
        smax = 2.0 * max(sx, sy * dx / dy)
        if smax > 0.0:
            dt = min(dt, cfl * dx / smax)
        lam = dt / dx
        mu_dt = dt * mu
        moved = False
        moving = False
        for i in range(a, b + 1):
            for j in range(c, d + 1):
                if rh[i, j] != 0.0:
                    moved = True
                hn = max(h[i, j] + lam * rh[i, j], 0.0)
                mn = m[i, j] + lam * rm[i, j]
                nn = n[i, j] + lam * rn[i, j]
                if hn > dry:
                    u = mn / hn + dt * g_x
                    v = nn / hn
                    s = math.sqrt(u * u + v * v)
                    if s > mu_dt:
                        f = (s - mu_dt) / s
                        mn = hn * u * f
                        nn = hn * v * f
                    else:
                        mn = 0.0
                        nn = 0.0
                else:
                    mn = 0.0
                    nn = 0.0
                if mn != 0.0 or nn != 0.0:
                    moving = True
                h[i, j] = hn
                m[i, j] = mn
                n[i, j] = nn
        t += dt
        steps += 1
        if not moved and not moving:
            break
    return t, steps
