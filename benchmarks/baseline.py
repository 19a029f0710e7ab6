r"""Speed-of-light baseline: a minimal hand-written numba loop of the same scheme.

First-order single-layer HLL (path-conservative fluctuation form, Davis wave speeds
u -+ sqrt(g_z h), the same at-rest rule at faces as pdeflow) with forward Euler, a CFL
time step recomputed every step, and the implicit set-valued Coulomb friction (gravity
along the bed included); wall or open ends; ends at rest (no mass moved and no momentum
left). It visits only the wet region plus one cell, fuses the update with the friction
and keeps no backup, no diagnostics and no failure checks: the smallest amount of work
this scheme can be done with. It is not part of the package; ``benchmarks/suite.py``
checks that it reproduces pdeflow's ``hll/first-order`` single-layer run.

Units: depths h [m], momenta hu [m^2/s], dx [m], times [s], g [m/s^2].
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def _fluct(hL: float, mL: float, hR: float, mR: float, g: float, dry: float):
    """HLL fluctuations (D^-_h, D^-_m, D^+_h, D^+_m) and max |speed| at one face."""
    uL = mL / hL if hL > dry else 0.0
    uR = mR / hR if hR > dry else 0.0
    cL = math.sqrt(g * max(hL, 0.0))
    cR = math.sqrt(g * max(hR, 0.0))
    sL = min(uL - cL, uR - cR)
    sR = max(uL + cL, uR + cR)
    smax = max(abs(sL), abs(sR))
    if mL == 0.0 and mR == 0.0:  # at rest on both sides: centred pressure, no mass
        dH = hR - hL
        return 0.0, 0.5 * g * hL * dH, 0.0, 0.5 * g * hR * dH, smax
    a0 = uR * hR - uL * hL
    a1 = uR * uR * hR + 0.5 * g * hR * hR - (uL * uL * hL + 0.5 * g * hL * hL)
    if sR - sL <= 0.0:
        c0 = 0.0
        c1 = 0.0
    else:
        c0 = (sR * abs(sL) - sL * abs(sR)) / (sR - sL)
        c1 = (abs(sR) - abs(sL)) / (sR - sL)
    dm0 = 0.5 * (a0 - (c0 * (hR - hL) + c1 * a0))
    dm1 = 0.5 * (a1 - (c0 * (mR - mL) + c1 * a1))
    return dm0, dm1, a0 - dm0, a1 - dm1, smax


@njit(cache=True)
def run_to_rest(h: np.ndarray, m: np.ndarray, dx: float, t_end: float, g_z: float,
                g_x: float, tan_phi: float, cfl: float, wall_left: bool,
                wall_right: bool, dry: float = 1e-6):
    """Advance (h, m) in place until rest or ``t_end``; returns (t [s], steps)."""
    n = h.shape[0]
    rh = np.zeros(n)
    rm = np.zeros(n)
    t = 0.0
    steps = 0
    mu = g_z * tan_phi
    while t < t_end:
        lo = 0
        while lo < n and h[lo] <= dry:
            lo += 1
        if lo == n:
            break
        hi = n - 1
        while h[hi] <= dry:
            hi -= 1
        a = max(lo - 1, 0)
        b = min(hi + 1, n - 1)
        for i in range(a, b + 1):
            rh[i] = 0.0
            rm[i] = 0.0
        smax = 0.0
        for i in range(max(lo, 1), b + 1):
            dm0, dm1, dp0, dp1, s = _fluct(h[i - 1], m[i - 1], h[i], m[i], g_z, dry)
            smax = max(smax, s)
            rh[i - 1] -= dm0
            rm[i - 1] -= dm1
            rh[i] -= dp0
            rm[i] -= dp1
        if lo == 0:
            dm0, dm1, dp0, dp1, s = _fluct(h[0], -m[0] if wall_left else m[0], h[0],
                                           m[0], g_z, dry)
            smax = max(smax, s)
            rh[0] -= dp0
            rm[0] -= dp1
        if hi == n - 1:
            dm0, dm1, dp0, dp1, s = _fluct(h[n - 1], m[n - 1], h[n - 1],
                                           -m[n - 1] if wall_right else m[n - 1], g_z, dry)
            smax = max(smax, s)
            rh[n - 1] -= dm0
            rm[n - 1] -= dm1
        dt = t_end - t
        if smax > 0.0:
            dt = min(dt, cfl * dx / smax)
        lam = dt / dx
        mu_dt = dt * mu
        moved = False
        moving = False
        for i in range(a, b + 1):
            if rh[i] != 0.0:
                moved = True
            hn = h[i] + lam * rh[i]
            mn = m[i] + lam * rm[i]
            hn = max(hn, 0.0)
            if hn > dry:
                v = mn / hn + dt * g_x
                if v > mu_dt:
                    v -= mu_dt
                elif v < -mu_dt:
                    v += mu_dt
                else:
                    v = 0.0
                mn = hn * v
            else:
                mn = 0.0
            if mn != 0.0:
                moving = True
            h[i] = hn
            m[i] = mn
        t += dt
        steps += 1
        if not moved and not moving:
            break
    return t, steps
