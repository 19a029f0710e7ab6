"""Vectorised numpy implementation of the method-of-lines rate (py-pde's numpy backend).

An independent second implementation of the same formulas as the numba kernels in
:mod:`pdeflow.numerics.hll` and :mod:`pdeflow.numerics.advection`, written over whole
arrays of faces (the models' source rates have their numpy twins beside their kernels,
e.g. :func:`pdeflow.models.two_layer.rates.source_rate_two_layer_np`). It serves py-pde's
``numpy`` backend and, in the tests, as a cross-check of the compiled kernels.
"""

from __future__ import annotations

import numpy as np

from . import layout as L


def velocity_np(h: np.ndarray, m: np.ndarray, dry: float) -> np.ndarray:
    """Depth-averaged velocity m/h [m/s] where h > dry [m], else 0 (over arrays)."""
    return np.where(h > dry, m / np.where(h > dry, h, 1.0), 0.0)


def _with_ghosts(q: np.ndarray, bc_left: int, bc_right: int) -> np.ndarray:
    """State with one ghost cell per side (walls mirror momenta, open copies)."""
    ext = np.concatenate([q[:, :1], q, q[:, -1:]], axis=1)
    for k in range(1, q.shape[0], 2):
        if bc_left == L.BC_WALL:
            ext[k, 0] = -ext[k, 0]
        if bc_right == L.BC_WALL:
            ext[k, -1] = -ext[k, -1]
    return ext


def _hll_split(sL, sR, dq, a):
    """HLL fluctuations D-, D+ for one (mass, momentum) pair over all faces."""
    width = np.where(sR - sL > 0, sR - sL, 1.0)
    dm = np.where(sL >= 0, 0.0, np.where(sR <= 0, a, sL / width * (sR * dq - a)))
    dm = np.where(sR - sL > 0, dm, 0.0)
    dp = np.where(sR - sL > 0, a - dm, 0.0)
    return dm, dp


def _at_uncovered_steps(left, right, ul, ur, sL, sR, a0, a1, dH, g, dry, fluct):
    """The upper layer's fluctuations (D-_h1, D+_h1, D-_h1u1, D+_h1u1) with those of
    :func:`pdeflow.models.two_layer.flux.upper_layer_at_uncovered_step` where the lower layer is
    at rest on both sides of a face and steps above the upper layer's surface on one
    side; ``fluct`` (the flux's own) elsewhere."""
    h1l, h1r, h2l, h2r = left[0], right[0], left[2], right[2]
    top = np.maximum(h2l, h2r)
    s_l = h1l + h2l - top
    s_r = h1r + h2r - top
    at = ((left[3] == 0.0) & (right[3] == 0.0) & (h2r - h2l != 0.0)
          & ((s_l <= 0.0) | (s_r <= 0.0)))
    s_l = np.maximum(s_l, 0.0)
    s_r = np.maximum(s_r, 0.0)
    f_l, f_r = s_l * ul, s_r * ur
    pressure = g * 0.5 * (h1l + h1r) * dH
    mass = f_l + _hll_split(sL, sR, s_r - s_l, f_r - f_l)[0]
    mom = f_l * ul + _hll_split(sL, sR, f_r - f_l, f_r * ur - f_l * ul)[0]
    share_l = _hll_split(sL, sR, 0.0 * pressure, pressure)[0]  # the flux's share of it
    share_r = pressure - share_l
    # both wet: the thinner side gets at most the share its own depth carries, the
    # thicker side the rest (as pvm.upper_layer_at_uncovered_step)
    both = (h1l > dry) & (h1r > dry)
    with np.errstate(divide="ignore", invalid="ignore"):
        h1bar = 0.5 * (h1l + h1r)
        thin_l = np.where(both & (h1l < h1r), share_l * h1l / h1bar, share_l)
        thin_r = np.where(both & (h1l >= h1r), share_r * h1r / h1bar, share_r)
    share_l, share_r = (np.where(both & (h1l >= h1r), pressure - thin_r, thin_l),
                        np.where(both & (h1l < h1r), pressure - thin_l, thin_r))
    # a side without upper layer gets no share of the hydrostatic jump
    share_l = np.where(h1l > dry, share_l, 0.0)
    share_r = np.where(h1r > dry, share_r, 0.0)
    dm0 = mass - ul * h1l
    dm1 = mom - ul * ul * h1l + share_l
    dp1 = ur * ur * h1r - ul * ul * h1l - (mom - ul * ul * h1l) + share_r
    dm0_, dp0_, dm1_, dp1_ = fluct
    return (np.where(at, dm0, dm0_), np.where(at, a0 - dm0, dp0_),
            np.where(at, dm1, dm1_), np.where(at, dp1, dp1_))


def advection_rate(q: np.ndarray, dx: float, bc: tuple[int, int], g: float,
                   dry: float, r: float | None) -> tuple[np.ndarray, float]:
    """HLL advection rate of a single-layer (r is None) or two-layer state, and the
    largest wave speed over the faces [m/s] (for the CFL condition)."""
    ext = _with_ghosts(q, *bc)
    left = ext[:, :-1]
    right = ext[:, 1:]
    n_layers = q.shape[0] // 2
    hs_l = [np.maximum(left[2 * k], 0.0) for k in range(n_layers)]
    hs_r = [np.maximum(right[2 * k], 0.0) for k in range(n_layers)]
    us_l = [velocity_np(left[2 * k], left[2 * k + 1], dry) for k in range(n_layers)]
    us_r = [velocity_np(right[2 * k], right[2 * k + 1], dry) for k in range(n_layers)]
    HL = sum(hs_l)
    HR = sum(hs_r)
    cL = np.sqrt(g * HL)
    cR = np.sqrt(g * HR)

    def extremes(hs, us):
        if n_layers == 1:
            return us[0], us[0]
        u1 = np.where(hs[0] > dry, us[0], us[1])
        u2 = np.where(hs[1] > dry, us[1], us[0])
        return np.minimum(u1, u2), np.maximum(u1, u2)

    loL, hiL = extremes(hs_l, us_l)
    loR, hiR = extremes(hs_r, us_r)
    sL = np.minimum(loL - cL, loR - cR)
    sR = np.maximum(hiL + cL, hiR + cR)
    dH = HR - HL
    fluct_m = []
    fluct_p = []
    for k in range(n_layers):
        hl, hr = left[2 * k], right[2 * k]
        ml, mr = left[2 * k + 1], right[2 * k + 1]
        ul, ur = us_l[k], us_r[k]
        if n_layers == 1:
            dpress = dH  # g h dH split by own depth at rest
            a1 = ur * ur * hr + 0.5 * g * hr * hr - ul * ul * hl - 0.5 * g * hl * hl
        elif k == 0:
            dpress = dH
            a1 = ur * ur * hr - ul * ul * hl + g * 0.5 * (hl + hr) * dH
        else:
            dpress = (right[2] - left[2]) + r * (right[0] - left[0])
            a1 = ur * ur * hr - ul * ul * hl + g * 0.5 * (hl + hr) * dpress
        a0 = ur * hr - ul * hl
        dm0, dp0 = _hll_split(sL, sR, hr - hl, a0)
        dm1, dp1 = _hll_split(sL, sR, mr - ml, a1)
        if n_layers == 2 and k == 0:
            dm0, dp0, dm1, dp1 = _at_uncovered_steps(left, right, ul, ur, sL, sR, a0, a1,
                                                     dH, g, dry, (dm0, dp0, dm1, dp1))
        rest = (ml == 0.0) & (mr == 0.0)
        dm0 = np.where(rest, 0.0, dm0)
        dp0 = np.where(rest, 0.0, dp0)
        dm1 = np.where(rest, 0.5 * g * hl * dpress, dm1)
        dp1 = np.where(rest, 0.5 * g * hr * dpress, dp1)
        fluct_m += [dm0, dm1]
        fluct_p += [dp0, dp1]
    dmin = np.array(fluct_m)  # shape (fields, faces)
    dplus = np.array(fluct_p)
    smax = float(np.max(np.maximum(np.abs(sL), np.abs(sR))))
    return -(dplus[:, :-1] + dmin[:, 1:]) / dx, smax


def basal_accel_np(P: np.ndarray, base: int, h: np.ndarray, gw: np.ndarray,
                   hm: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Friction deceleration [m/s^2] of the basal law at ``base`` over arrays (the numpy
    twin of :func:`pdeflow.numerics.rheology.basal_accel`; depths > 0 where used)."""
    code = int(P[base + L.LAW_CODE])
    mu1, dmu = P[base + L.LAW_MU1], P[base + L.LAW_DMU]
    hp = np.maximum(h, 1e-300)
    mu_static = mu1 + (dmu / (1.0 + hp * P[base + L.LAW_INV_L])
                       if code == L.FRICTION_POULIQUEN else 0.0)
    if code in (L.FRICTION_COULOMB, L.FRICTION_VOELLMY):
        mu = np.full_like(hp, mu1)
    else:
        s0 = P[base + L.LAW_S0] * hp * np.sqrt(hp)
        mu = mu1 + dmu * s / np.maximum(s0 + s, 1e-300)
        if code == L.FRICTION_POULIQUEN:
            mu = np.where(s < P[base + L.LAW_BETA_G] * np.sqrt(hp), mu_static, mu)
    mu = np.where(s > 0.0, mu, mu_static)
    return gw * mu + P[base + L.LAW_DRAG] * s * s / np.maximum(hm, 1e-300)
