r"""The source stages with a rate-dependent basal law (:mod:`.rheology`), as kernels of
their own.

A run with Coulomb friction (the paper's) compiles the kernels of :mod:`.source_stage`
and :mod:`.friction` exactly as before: the laws add nothing to their code, their call
trees or their compile time. A run with another law (``friction_law`` of either model)
gets the kernels here, through the model's second bundle
(:data:`pdeflow.numerics.bundles.TWO_LAYER_LAWS`, ``SINGLE_LAYER_LAWS``); which of the
rate-dependent laws is a code in the parameter vector, read at run time, so a sweep over
laws and their parameters compiles once.

The two-layer stage (31)-(34) is long and only its friction (32) changes: its kernels
here are the same Python code as :func:`.source_stage.sources_two_layer` and its callees
with :func:`implicit_friction_law` in place of
:func:`.friction.implicit_friction` (:func:`_with_callees`); the disk cache keys them
by that code and their callees', so they never mix with the Coulomb ones.
"""

from __future__ import annotations

import types
from collections.abc import Callable
from typing import Any

import numpy as np

from . import friction, source_stage
from . import layout_single_layer as S
from . import layout_two_layer as T
from .compiled import PARAMS, STATE, VECTOR, cached, f8, i8, kernel
from .rheology import friction_two_layer_law, law_block, law_velocity
from .source_stage import _close_stage
from .sources import _drag_root
from .state import velocity


def _with_callees(dispatcher: Any, name: str, **callees: Any) -> Callable:
    """The Python function of the kernel ``dispatcher`` with the global names
    ``callees`` bound to other kernels, named ``name`` in this module."""
    f = dispatcher.py_func
    scope = {**f.__globals__, **callees}
    new = types.FunctionType(f.__code__, scope, name, f.__defaults__, f.__closure__)
    new.__qualname__ = name
    new.__module__ = __name__
    new.__doc__ = f"{f.__name__} with a rate-dependent basal law (see {__name__})."
    return new


@cached
def implicit_friction_law(b1, b2, h1, h2, dt, P, f, k, c):
    """:func:`pdeflow.numerics.friction.implicit_friction` with the lower layer's bed
    friction given by the basal law at ``T.LAW``
    (:func:`pdeflow.numerics.rheology.friction_two_layer_law`; the law sees the total
    depth h1 + h2 and the weight of both layers)."""
    r = P[T.R]
    g = P[T.G_Z]
    dry = P[T.DRY]
    wet1 = h1 > dry
    wet2 = h2 > dry
    if wet1 and wet2:
        m1 = r * h1
        if f != 0.0:
            b1 = b1 - dt * f / m1
            b2 = b2 + dt * f / h2
        kdt = dt * k * r * g * h1 * P[T.TAN_INT]
        return friction_two_layer_law(b1, b2, m1, h2, kdt, dt * c, dt, g, h1 + h2,
                                      law_block(P, T.LAW))
    if wet1:
        # no lower layer: the upper layer rubs on the bed with the interface law (22)
        m1 = r * h1
        kdt = dt * k * r * g * h1 * P[T.TAN_INT]
        u1 = _drag_root(m1 * abs(b1) - kdt, m1, dt * c)
        return (u1 if b1 > 0.0 else -u1), 0.0
    if wet2:
        gw = g * (h2 + r * max(h1, 0.0)) / h2
        return 0.0, law_velocity(b2, h2 + max(h1, 0.0), gw, h2, dt, law_block(P, T.LAW))
    return 0.0, 0.0


bisect_fextra_law = cached(_with_callees(
    friction.bisect_fextra, "bisect_fextra_law", implicit_friction=implicit_friction_law))
restore_hyperbolicity_law = cached(_with_callees(
    friction.restore_hyperbolicity, "restore_hyperbolicity_law",
    implicit_friction=implicit_friction_law, bisect_fextra=bisect_fextra_law))
predictor_two_layer_law = kernel(STATE, f8, PARAMS, i8, i8)(_with_callees(
    friction.predictor_two_layer, "predictor_two_layer_law",
    implicit_friction=implicit_friction_law))
sources_two_layer_law = kernel(STATE, f8, f8, PARAMS, VECTOR, i8, i8)(_with_callees(
    source_stage.sources_two_layer, "sources_two_layer_law",
    implicit_friction=implicit_friction_law,
    restore_hyperbolicity=restore_hyperbolicity_law))
source_stage_two_layer_law = kernel(STATE, f8, f8, PARAMS, VECTOR)(_with_callees(
    source_stage.source_stage_two_layer, "source_stage_two_layer_law",
    sources_two_layer=sources_two_layer_law))


@kernel(STATE, f8, f8, PARAMS, VECTOR, i8, i8)
def sources_single_law(q: np.ndarray, dt: float, t: float, P: np.ndarray,
                       diag: np.ndarray, lo: int, hi: int) -> None:
    """:func:`pdeflow.numerics.source_stage.sources_single` with the basal law at
    ``S.LAW``: gravity along the bed and the law's set-valued implicit friction."""
    g = P[S.G_Z]
    gx = P[S.G_X]
    dry = P[S.DRY]
    law = law_block(P, S.LAW)
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
            u = law_velocity(u + dt * gx, h, g, h, dt, law)
        m = h * u if h > dry else 0.0
        if m != 0.0:
            moving = True
            if h > P[S.SLOW_H] and abs(u) >= P[S.SLOW_U]:
                fast = True
        q[0, i] = h
        q[1, i] = m
    _close_stage(diag, t, moving, fast, False, False, False)


@kernel(STATE, f8, f8, PARAMS, VECTOR)
def source_stage_single_law(q: np.ndarray, dt: float, t: float, P: np.ndarray,
                            diag: np.ndarray) -> None:
    """:func:`sources_single_law` on every cell (the post-step hook's kernel)."""
    sources_single_law(q, dt, t, P, diag, 0, q.shape[1] - 1)


@kernel(STATE, f8, PARAMS, i8, i8)
def predictor_single_law(q: np.ndarray, dt: float, P: np.ndarray, lo: int,
                         hi: int) -> None:
    """:func:`pdeflow.numerics.friction.predictor_single` with the basal law: zero the
    momentum of cells that the law's implicit friction would hold at rest."""
    dry = P[S.DRY]
    law = law_block(P, S.LAW)
    for i in range(lo, hi + 1):
        h = max(q[0, i], 0.0)
        if h > dry:
            u = law_velocity(q[1, i] / h + dt * P[S.G_X], h, P[S.G_Z], h, dt, law)
            if u == 0.0:
                q[1, i] = 0.0


__all__ = ["implicit_friction_law", "sources_two_layer_law",
           "source_stage_two_layer_law", "predictor_two_layer_law", "sources_single_law",
           "source_stage_single_law", "predictor_single_law"]
