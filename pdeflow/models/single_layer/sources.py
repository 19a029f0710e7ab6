"""The single layer's source stage: gravity along the bed and implicit basal friction.

The stage of the split scheme on the wet cells (``sources``) and on every cell
(``source_stage``, the post-step hook's kernel) and MUSCL's friction predictor, built
per basal law by :func:`stage_kernels` (Coulomb's closed form, or a rate-dependent law
of :mod:`pdeflow.numerics.rheology` whose kernels are compiled in as constants).
Friction is applied implicitly and set-valued: a layer whose drive is below the static
friction stops in that step.
"""

from __future__ import annotations

import functools
from typing import Any

from ...numerics import layout as L
from ...numerics.compiled import PARAMS, STATE, VECTOR, cached, f8, i8, specialise
from ...numerics.implicit import coulomb_single
from ...numerics.rheology import BasalLaw, law_block, law_velocity
from ...numerics.state import velocity
from . import layout as S


@functools.cache
def stage_kernels(law: BasalLaw | None) -> tuple[Any, Any, Any]:
    """The single layer's source-stage kernels with the basal law ``law`` (None:
    Coulomb's closed-form step, tan(phi_b)), compiled with the law's kernels as
    constants: the stage on the cells lo..hi ``(q, dt, t, P, diag, lo, hi)``, the same
    on every cell ``(q, dt, t, P, diag)`` (the post-step hook's kernel) and MUSCL's
    friction predictor ``(q, dt, P, lo, hi)``."""
    return _stage(*friction_step(law))


def friction_step(law: BasalLaw | None) -> tuple[Any, Any, bool]:
    """``(step_friction, after_friction, coulomb)``: the single layer's implicit basal
    friction with the law ``law`` (None: Coulomb's), as the stages take it (see
    :func:`_stage`); the 2D stage (:mod:`.sources_2d`) applies ``after_friction`` to the
    speed."""
    if law is None:
        return basal_friction, basal_velocity, True
    return law_friction, _law_step(law_velocity(law)), False


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
def law_friction(dt, g, P):
    """What a basal law needs of a step: its block of ``P`` (read once per stage)."""
    return law_block(P, S.LAW)


@functools.cache
def _law_step(velocity_after: Any) -> Any:
    """:func:`basal_velocity` with a law: its velocity after friction (its depth is
    the depth it sees and its mass depth; g_z its weight per mass)."""

    def basal_velocity_law(b, h, dt, g, law):
        return velocity_after(b, h, g, h, dt, law)

    return specialise(basal_velocity_law, helper=True, inline="always")


def _stage(step_friction: Any, after_friction: Any,
           coulomb: bool = False) -> tuple[Any, Any, Any]:
    """The stage kernels with friction ``after_friction(b, h, dt, g, step_friction(dt,
    g, P))`` (see :func:`basal_friction`, :func:`basal_velocity`); ``coulomb``: named
    as the module's names they are bound to (a new interpreter imports them)."""

    def named(kernel: Any) -> str | None:
        return kernel.__name__ if coulomb else None

    def sources_single(q, dt, t, P, diag, lo, hi):
        """Implicit basal friction (and gravity along the bed) of the single layer on
        the cells ``lo..hi``."""
        g = P[S.G_Z]
        gx = P[S.G_X]
        dry = P[S.DRY]
        friction = step_friction(dt, g, P)
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
                u = after_friction(u + dt * gx, h, dt, g, friction)
            m = h * u if h > dry else 0.0
            if m != 0.0:
                moving = True
                if h > P[S.SLOW_H] and abs(u) >= P[S.SLOW_U]:
                    fast = True
            q[0, i] = h
            q[1, i] = m
        _close_stage(diag, t, moving, fast)

    sources = specialise(sources_single, STATE, f8, f8, PARAMS, VECTOR, i8, i8,
                         name=named(sources_single))

    def source_stage_single(q, dt, t, P, diag):
        """:func:`sources_single` on every cell."""
        sources(q, dt, t, P, diag, 0, q.shape[1] - 1)

    def predictor_single(q, dt, P, lo, hi):
        """Zero the momentum of cells that the implicit friction would hold at rest, in
        place, in the cells ``lo..hi`` (MUSCL's intermediate stage, as
        :func:`pdeflow.models.two_layer.friction.friction_kernels`' predictor)."""
        dry = P[S.DRY]
        friction = step_friction(dt, P[S.G_Z], P)
        for i in range(lo, hi + 1):
            h = max(q[0, i], 0.0)
            if h > dry:
                u = after_friction(q[1, i] / h + dt * P[S.G_X], h, dt, P[S.G_Z], friction)
                if u == 0.0:
                    q[1, i] = 0.0

    return (
        sources, specialise(source_stage_single, STATE, f8, f8, PARAMS, VECTOR,
                            name=named(source_stage_single)),
        specialise(predictor_single, STATE, f8, PARAMS, i8, i8,
                   name=named(predictor_single)))


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


sources_single, source_stage_single, predictor_single = stage_kernels(None)
"""the Coulomb stage's kernels (the paper's baseline)"""
