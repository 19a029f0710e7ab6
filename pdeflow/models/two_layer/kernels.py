"""The two-layer model's kernels as :class:`~pdeflow.numerics.model_kernels.ModelKernels`
bundles: what the model-free stepping loop, advection stage and method-of-lines rate
take of it, one bundle per basal law (:func:`kernels`)."""

from __future__ import annotations

import functools

import numpy as np

from ...numerics.model_kernels import ModelKernels
from ...numerics.rheology import BasalLaw
from ...numerics.vectorized import advection_rate
from . import layout as T
from .flux import cell_jump, face, fluctuations
from .rates import fluctuations_np, source_rate, source_rate_np
from .sources import stage_kernels


def _constants(P: np.ndarray) -> tuple[float, float, float]:
    return float(P[T.G_Z]), float(P[T.R]), float(P[T.DRY])


def _numpy_advection(q: np.ndarray, dx: float, bc: tuple[int, int],
                     P: np.ndarray) -> tuple[np.ndarray, float]:
    return advection_rate(q, dx, bc, fluctuations_np, P[T.G_Z], P[T.DRY], P[T.R])


@functools.cache
def kernels(law: BasalLaw | None = None) -> ModelKernels:
    """System (24) with closure (25) and the basal law ``law`` (None: the paper's
    Coulomb friction): the fluctuations of :mod:`.flux`, the source stages (31)-(34) of
    :mod:`.sources`."""
    sources, source_stage, predictor = stage_kernels(law)
    return ModelKernels(
        fields=4, face=face, fluctuations=fluctuations, cell_jump=cell_jump,
        sources=sources, source_stage=source_stage, predictor=predictor,
        mol_sources=source_rate(law), numpy_advection=_numpy_advection,
        numpy_sources=functools.partial(source_rate_np, law=law), constants=_constants)


KERNELS = kernels()
"""the paper's system with Coulomb friction at the bed"""
