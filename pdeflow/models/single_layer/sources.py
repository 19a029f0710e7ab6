"""The single layer's source stage: gravity along the bed and implicit basal friction.

The stage of the split scheme on the wet cells (:func:`sources_single`) and on every
cell (:func:`source_stage_single`, the post-step hook's kernel), MUSCL's friction
predictor, and the same three with a rate-dependent basal law
(:mod:`pdeflow.numerics.rheology`; the Coulomb kernels' code is reused with the law's
friction helpers, :func:`pdeflow.numerics.callees.with_callees`). Friction is applied
implicitly and set-valued: a layer whose drive is below the static friction stops in
that step.
"""

from __future__ import annotations

import numpy as np

from ...numerics import layout as L
from ...numerics.callees import with_callees
from ...numerics.compiled import PARAMS, STATE, VECTOR, cached, f8, i8, kernel
from ...numerics.implicit import coulomb_single
from ...numerics.rheology import law_block, law_velocity
from ...numerics.state import velocity
from . import layout as S


@kernel(STATE, f8, f8, PARAMS, VECTOR)
def source_stage_single(q: np.ndarray, dt: float, t: float, P: np.ndarray,
                        diag: np.ndarray) -> None:
    """Implicit Coulomb friction (and gravity along the bed) for the single layer."""
    sources_single(q, dt, t, P, diag, 0, q.shape[1] - 1)


@kernel(STATE, f8, f8, PARAMS, VECTOR, i8, i8)
def sources_single(q: np.ndarray, dt: float, t: float, P: np.ndarray,
                   diag: np.ndarray, lo: int, hi: int) -> None:
    """:func:`source_stage_single` on the cells ``lo..hi`` only."""
    g = P[S.G_Z]
    gx = P[S.G_X]
    dry = P[S.DRY]
    friction = basal_friction(dt, g, P)
    moving = False
    fast = False
    for i in range(lo, hi + 1):
        h = q[0, i]
        m = q[1, i]
        if h == 0.0 and m == 0.0:
            continue
        h = max(h, 0.0)
        u = velocity(h, m, dry)
        if dt > 0.0 and h > dry:
            u = basal_velocity(u + dt * gx, h, dt, g, friction)
        m = h * u if h > dry else 0.0
        if m != 0.0:
            moving = True
            if h > P[S.SLOW_H] and abs(u) >= P[S.SLOW_U]:
                fast = True
        q[0, i] = h
        q[1, i] = m
    _close_stage(diag, t, moving, fast)


@cached(inline="always")
def basal_friction(dt, g, P):
    """What the single layer's implicit Coulomb friction needs of a step: mu g_z dt
    [m/s] (computed once per stage)."""
    return dt * g * P[S.TAN_B]


@cached(inline="always")
def basal_velocity(b, h, dt, g, friction):
    """The velocity [m/s] after the implicit basal friction of a step from ``b`` [m/s]
    (set-valued: 0 where |b| <= mu g_z dt)."""
    return coulomb_single(b, friction)


@cached(inline="always")
def _close_stage(diag, t, moving, fast):
    """Book a source stage ending at ``t`` [s] in ``diag``: the times of the last motion
    (``moving``: the layer has momentum; ``fast``: faster than SLOW_U where deeper than
    SLOW_H), whether it changed anything."""
    if moving:
        diag[S.D_MOVE] = t
    if fast:
        diag[S.D_FAST] = t
    diag[L.D_CHANGED] = 1.0 if moving else 0.0
    diag[L.D_T] = t
    diag[L.D_STEPS] += 1.0


@kernel(STATE, f8, PARAMS, i8, i8)
def predictor_single(q: np.ndarray, dt: float, P: np.ndarray, lo: int, hi: int) -> None:
    """Zero the momentum of cells that the implicit Coulomb friction would hold at
    rest, in place, in the cells ``lo..hi`` (MUSCL's intermediate stage, as
    :func:`pdeflow.models.two_layer.friction.predictor_two_layer`)."""
    dry = P[S.DRY]
    for i in range(lo, hi + 1):
        h = max(q[0, i], 0.0)
        if h > dry:
            u = coulomb_single(q[1, i] / h + dt * P[S.G_X],
                               dt * P[S.G_Z] * P[S.TAN_B])
            if u == 0.0:
                q[1, i] = 0.0


@cached(inline="always")
def basal_friction_law(dt, g, P):
    """What the basal law needs of a step: its block of ``P`` (read once per stage)."""
    return law_block(P, S.LAW)


@cached(inline="always")
def basal_velocity_law(b, h, dt, g, law):
    """:func:`basal_velocity` with the basal law."""
    return law_velocity(b, h, g, h, dt, law)


sources_single_law = kernel(STATE, f8, f8, PARAMS, VECTOR, i8, i8)(with_callees(
    __name__, sources_single, "sources_single_law",
    basal_friction=basal_friction_law, basal_velocity=basal_velocity_law))


@kernel(STATE, f8, f8, PARAMS, VECTOR)
def source_stage_single_law(q: np.ndarray, dt: float, t: float, P: np.ndarray,
                            diag: np.ndarray) -> None:
    """:func:`sources_single_law` on every cell (the post-step hook's kernel)."""
    sources_single_law(q, dt, t, P, diag, 0, q.shape[1] - 1)


@kernel(STATE, f8, PARAMS, i8, i8)
def predictor_single_law(q: np.ndarray, dt: float, P: np.ndarray, lo: int,
                         hi: int) -> None:
    """:func:`predictor_single` with the basal law: zero the
    momentum of cells that the law's implicit friction would hold at rest."""
    dry = P[S.DRY]
    law = law_block(P, S.LAW)
    for i in range(lo, hi + 1):
        h = max(q[0, i], 0.0)
        if h > dry:
            u = law_velocity(q[1, i] / h + dt * P[S.G_X], h, P[S.G_Z], h, dt, law)
            if u == 0.0:
                q[1, i] = 0.0
