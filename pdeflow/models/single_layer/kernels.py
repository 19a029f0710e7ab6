"""The single layer's kernels as :class:`~pdeflow.numerics.model_kernels.ModelKernels`
bundles: what the model-free stepping loop, advection stage and method-of-lines rate
take of it."""

from __future__ import annotations

import dataclasses

import numpy as np

from ...numerics.model_kernels import ModelKernels
from ...numerics.vectorized import advection_rate
from . import layout as S
from .flux import cell_jump, face, fluctuations
from .rates import fluctuations_np, source_rate_single, source_rate_single_np
from .sources import (
    predictor_single,
    predictor_single_law,
    source_stage_single,
    source_stage_single_law,
    sources_single,
    sources_single_law,
)


def _constants(P: np.ndarray) -> tuple[float, float, float]:
    return float(P[S.G_Z]), 0.0, float(P[S.DRY])


def _numpy_advection(q: np.ndarray, dx: float, bc: tuple[int, int],
                     P: np.ndarray) -> tuple[np.ndarray, float]:
    return advection_rate(q, dx, bc, fluctuations_np, P[S.G_Z], P[S.DRY])


KERNELS = ModelKernels(
    fields=2, face=face, fluctuations=fluctuations, cell_jump=cell_jump,
    sources=sources_single, source_stage=source_stage_single, predictor=predictor_single,
    mol_sources=source_rate_single, numpy_advection=_numpy_advection,
    numpy_sources=source_rate_single_np, constants=_constants)
"""the Savage-Hutter-type layer with implicit Coulomb friction"""

LAW_KERNELS = dataclasses.replace(
    KERNELS, sources=sources_single_law, source_stage=source_stage_single_law,
    predictor=predictor_single_law)
""":data:`KERNELS` with a rate-dependent basal law (:mod:`.sources`)"""
