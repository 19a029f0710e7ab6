"""The two-layer model's kernels as :class:`~pdeflow.numerics.model_kernels.ModelKernels`
bundles: what the model-free stepping loop, advection stage and method-of-lines rate
take of it."""

from __future__ import annotations

import dataclasses

import numpy as np

from ...numerics.model_kernels import ModelKernels
from ...numerics.vectorized import advection_rate
from . import layout as T
from .flux import cell_jump, face, fluctuations
from .friction import predictor_two_layer
from .laws import predictor_two_layer_law, source_stage_two_layer_law, sources_two_layer_law
from .rates import fluctuations_np, source_rate_two_layer, source_rate_two_layer_np
from .sources import source_stage_two_layer, sources_two_layer


def _constants(P: np.ndarray) -> tuple[float, float, float]:
    return float(P[T.G_Z]), float(P[T.R]), float(P[T.DRY])


def _numpy_advection(q: np.ndarray, dx: float, bc: tuple[int, int],
                     P: np.ndarray) -> tuple[np.ndarray, float]:
    return advection_rate(q, dx, bc, fluctuations_np, P[T.G_Z], P[T.DRY], P[T.R])


KERNELS = ModelKernels(
    fields=4, face=face, fluctuations=fluctuations, cell_jump=cell_jump,
    sources=sources_two_layer, source_stage=source_stage_two_layer,
    predictor=predictor_two_layer, mol_sources=source_rate_two_layer,
    numpy_advection=_numpy_advection, numpy_sources=source_rate_two_layer_np,
    constants=_constants)
"""system (24) with closure (25): the fluctuations of :mod:`.flux`, the source stages
(31)-(34) of :mod:`.sources`"""

LAW_KERNELS = dataclasses.replace(
    KERNELS, sources=sources_two_layer_law, source_stage=source_stage_two_layer_law,
    predictor=predictor_two_layer_law)
""":data:`KERNELS` with a rate-dependent basal law (:mod:`.laws`); the method-of-lines
rates read the law's code themselves"""
