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
from .friction import FP_MODE, friction_params
from .rheology import friction_two_layer_law, law_block, law_velocity


def _with_callees(dispatcher: Any, name: str, **callees: Any) -> Callable:
    """The Python function of the kernel ``dispatcher`` with the global names
    ``callees`` bound to other kernels, named ``name`` in this module (with
    ``NUMBA_DISABLE_JIT=1`` the kernels are Python functions)."""
    f = getattr(dispatcher, "py_func", dispatcher)
    scope = {**f.__globals__, **callees}
    new = types.FunctionType(f.__code__, scope, name, f.__defaults__, f.__closure__)
    new.__qualname__ = name
    new.__module__ = __name__
    new.__doc__ = f"{f.__name__} with a rate-dependent basal law (see {__name__})."
    return new


@cached(inline="always")
def friction_params_law(P):
    """:func:`pdeflow.numerics.friction.friction_params` with the basal law's block
    (:func:`pdeflow.numerics.rheology.law_block`) at the position FP_LAW."""
    return friction_params(P) + (law_block(P, T.LAW),)


FP_LAW = FP_MODE + 1
"""position of the law's block in :func:`friction_params_law`' tuple"""


@cached(inline="always")
def bed_under_both_law(b1, b2, m1, h1, h2, kdt, cdt, dt, g, r, fp):
    """:func:`pdeflow.numerics.friction.bed_under_both` with the basal law of
    ``fp[FP_LAW]`` (:func:`pdeflow.numerics.rheology.friction_two_layer_law`; the law
    sees the total depth h1 + h2 and the weight of both layers)."""
    return friction_two_layer_law(b1, b2, m1, h2, kdt, cdt, dt, g, h1 + h2, fp[FP_LAW])


@cached(inline="always")
def bed_under_lower_law(b2, h1, h2, dt, g, r, fp):
    """:func:`pdeflow.numerics.friction.bed_under_lower` with the basal law."""
    gw = g * (h2 + r * max(h1, 0.0)) / h2
    return law_velocity(b2, h2 + max(h1, 0.0), gw, h2, dt, fp[FP_LAW])


implicit_friction_law = cached(_with_callees(
    friction.implicit_friction, "implicit_friction_law",
    bed_under_both=bed_under_both_law, bed_under_lower=bed_under_lower_law))
bisect_fextra_law = cached(_with_callees(
    friction.bisect_fextra, "bisect_fextra_law", implicit_friction=implicit_friction_law))
restore_to_edge_law = cached(_with_callees(
    friction.restore_to_edge, "restore_to_edge_law", bed_under_both=bed_under_both_law,
    implicit_friction=implicit_friction_law, bisect_fextra=bisect_fextra_law))
predictor_two_layer_law = kernel(STATE, f8, PARAMS, i8, i8)(_with_callees(
    friction.predictor_two_layer, "predictor_two_layer_law",
    implicit_friction=implicit_friction_law, friction_params=friction_params_law))
sources_two_layer_law = kernel(STATE, f8, f8, PARAMS, VECTOR, i8, i8)(_with_callees(
    source_stage.sources_two_layer, "sources_two_layer_law",
    implicit_friction=implicit_friction_law, friction_params=friction_params_law,
    restore_to_edge=restore_to_edge_law))
source_stage_two_layer_law = kernel(STATE, f8, f8, PARAMS, VECTOR)(_with_callees(
    source_stage.source_stage_two_layer, "source_stage_two_layer_law",
    sources_two_layer=sources_two_layer_law))


@cached(inline="always")
def basal_friction_law(dt, g, P):
    """What the basal law needs of a step: its block of ``P`` (read once per stage)."""
    return law_block(P, S.LAW)


@cached(inline="always")
def basal_velocity_law(b, h, dt, g, law):
    """:func:`pdeflow.numerics.source_stage.basal_velocity` with the basal law."""
    return law_velocity(b, h, g, h, dt, law)


sources_single_law = kernel(STATE, f8, f8, PARAMS, VECTOR, i8, i8)(_with_callees(
    source_stage.sources_single, "sources_single_law",
    basal_friction=basal_friction_law, basal_velocity=basal_velocity_law))


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
