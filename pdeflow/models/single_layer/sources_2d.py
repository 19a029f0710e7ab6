r"""The single layer's sources on a 2D grid: gravity along the plane and vector basal
friction.

State (h, hu, hv) on the flattened cells (:mod:`.two_d`). Gravity acts along the
plane's steepest descent: (g_x, g_y) = g sin(theta) (cos a, sin a), a the slope's
azimuth (``slope_azimuth_deg``; (g sin(theta), 0) at a = 0). Basal friction opposes the
velocity and is applied implicitly and set-valued, as in 1D (:mod:`.sources`): from the
explicit update **u*** = **u** + dt (g_x, g_y), the speed after the step is the 1D
law's step applied to the speed |**u***| (Coulomb: max(|**u***| - dt g_z mu, 0); a
rate-dependent law: its ``speed``), along **u***:

.. math:: \mathbf{u}^{n+1} = \frac{\mathbf{u}^*}{|\mathbf{u}^*|}\, s^{n+1}.

With v = 0, sqrt(u*^2) == |u*| and u*/|u*| == +-1 in IEEE arithmetic, so the update is
the 1D arithmetic to the bit (at a = 0, g_y = 0 adds nothing to v; at a = 90 deg g_x
is exactly 0, and the same holds with x and y exchanged). The method-of-lines rate
regularises the direction of the friction as the 1D one does, **u** / max(|**u**|,
mol_eps).
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np

from ...numerics import layout as L
from ...numerics.compiled import FIELDS, PARAMS, STATE, VECTOR, f8, i8, kernel, specialise
from ...numerics.rheology import BasalLaw, basal_accel, law_block
from ...numerics.state import velocity
from . import layout as S
from .sources import _close_stage, friction_step


@functools.cache
def vector_step(after_friction: Any) -> Any:
    """``step(a, b, h, dt, g, friction) -> (u, v)``: the velocity [m/s] after the
    implicit basal friction of a step from (a, b) [m/s], ``after_friction`` (the 1D
    step, :func:`.sources.friction_step`) applied to the speed, along (a, b)."""

    def vector_step_single(a, b, h, dt, g, friction):
        s = math.sqrt(a * a + b * b)
        if s == 0.0:
            return 0.0, 0.0
        s_new = after_friction(s, h, dt, g, friction)
        return a / s * s_new, b / s * s_new

    return specialise(vector_step_single, helper=True, inline="always")


@functools.cache
def stage_kernels_2d(law: BasalLaw | None) -> tuple[Any, Any, Any]:
    """The 2D source-stage kernels with the basal law ``law`` (None: Coulomb's): the
    stage on cells lo..hi ``(q, dt, t, P, book, fex, lo, hi)`` (a row of the loop's
    box, ``numerics.threads``), the same on every cell
    ``(q, dt, t, P, diag)`` and MUSCL's friction predictor ``(q, dt, P, lo, hi)``, as
    :func:`.sources.stage_kernels` gives them in 1D."""
    step_friction, after_friction, _ = friction_step(law)
    step = vector_step(after_friction)

    def sources_single_2d(q, dt, t, P, book, fex, lo, hi):
        """Gravity along the plane and implicit vector basal friction on the cells lo..hi,
        booked in ``book`` (no per-cell diagnostic: ``fex`` is not written)."""
        g = P[S.G_Z]
        gx = P[S.G_X]
        gy = P[S.G_Y]
        dry = P[S.DRY]
        friction = step_friction(dt, g, P)
        moving = False
        fast = False
        for i in range(lo, hi + 1):
            h = q[0, i]
            m = q[1, i]
            n = q[2, i]
            if h == 0.0 and m == 0.0 and n == 0.0:
                continue
            h = max(h, 0.0)
            u = velocity(h, m, dry)
            v = velocity(h, n, dry)
            if dt > 0.0 and h > dry:
                u, v = step(u + dt * gx, v + dt * gy, h, dt, g, friction)
            m = h * u if h > dry else 0.0
            n = h * v if h > dry else 0.0
            if m != 0.0 or n != 0.0:
                moving = True
                if h > P[S.SLOW_H] and math.sqrt(u * u + v * v) >= P[S.SLOW_U]:
                    fast = True
            q[0, i] = h
            q[1, i] = m
            q[2, i] = n
        _close_stage(book, t, moving, fast)

    sources = specialise(sources_single_2d, STATE, f8, f8, PARAMS, VECTOR, VECTOR, i8, i8)

    def source_stage_single_2d(q, dt, t, P, diag):
        """:func:`sources_single_2d` on every cell."""
        sources(q, dt, t, P, diag, diag[L.N_DIAG:], 0, q.shape[1] - 1)

    def predictor_single_2d(q, dt, P, lo, hi):
        """Zero the momenta of cells that the implicit friction would hold at rest, in
        place, in the cells lo..hi (MUSCL's intermediate stage)."""
        dry = P[S.DRY]
        g = P[S.G_Z]
        friction = step_friction(dt, g, P)
        for i in range(lo, hi + 1):
            h = max(q[0, i], 0.0)
            if h > dry:
                a = q[1, i] / h + dt * P[S.G_X]
                b = q[2, i] / h + dt * P[S.G_Y]
                s = math.sqrt(a * a + b * b)
                if s == 0.0 or after_friction(s, h, dt, g, friction) == 0.0:
                    q[1, i] = 0.0
                    q[2, i] = 0.0

    return (sources, specialise(source_stage_single_2d, STATE, f8, f8, PARAMS, VECTOR),
            specialise(predictor_single_2d, STATE, f8, PARAMS, i8, i8))


@kernel(VECTOR, VECTOR)
def fold_single_2d(diag: np.ndarray, book: np.ndarray) -> None:
    """Add a row's booking of :func:`stage_kernels_2d`'s stage (from zeros) to
    ``diag``: the times of the last motion [s] (the latest: never negative)."""
    diag[S.D_MOVE] = max(diag[S.D_MOVE], book[S.D_MOVE])
    diag[S.D_FAST] = max(diag[S.D_FAST], book[S.D_FAST])


@functools.cache
def source_rate_2d(law: BasalLaw | None) -> Any:
    """The kernel ``(q, rate, P)`` that adds gravity along the plane and the regularised basal
    friction of ``law`` (None: Coulomb's) along the velocity to ``rate`` (2D single
    layer; the 1D :func:`.rates.source_rate`'s arithmetic where v = 0)."""
    coulomb = law is None
    accel, block = (None, None) if coulomb else (basal_accel(law), law_block)

    def source_rate_single_2d(q, rate, P):
        for i in range(q.shape[1]):
            h = max(q[0, i], 0.0)
            if h > P[S.DRY]:
                u = q[1, i] / h
                v = q[2, i] / h
                s = math.sqrt(u * u + v * v)
                if coulomb:
                    f = P[S.G_Z] * h * P[S.TAN_B]
                else:
                    f = h * accel(block(P, S.LAW), h, P[S.G_Z], h, s)
                rate[1, i] += P[S.G_X] * h - f * u / max(s, P[S.MOL_EPS])
                rate[2, i] += P[S.G_Y] * h - f * v / max(s, P[S.MOL_EPS])

    return specialise(source_rate_single_2d, STATE, FIELDS, PARAMS)

