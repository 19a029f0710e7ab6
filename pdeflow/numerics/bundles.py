"""The kernels of the paper's two models, as :class:`.ModelKernels` bundles."""

from __future__ import annotations

import dataclasses

import numpy as np

from . import layout_single_layer as S
from . import layout_two_layer as T
from .advection import cell_jump_single, cell_jump_two_layer
from .friction import predictor_single, predictor_two_layer
from .law_stage import (
    predictor_single_law,
    predictor_two_layer_law,
    source_stage_single_law,
    source_stage_two_layer_law,
    sources_single_law,
    sources_two_layer_law,
)
from .model_kernels import ModelKernels
from .mol import source_rate_single, source_rate_two_layer
from .pvm import face_single, face_two_layer, fluctuations_single, fluctuations_two_layer
from .source_stage import (
    source_stage_single,
    source_stage_two_layer,
    sources_single,
    sources_two_layer,
)
from .vectorized import advection_rate, source_rate_single_np, source_rate_two_layer_np


def _two_layer_constants(P: np.ndarray) -> tuple[float, float, float]:
    return float(P[T.G_Z]), float(P[T.R]), float(P[T.DRY])


def _single_constants(P: np.ndarray) -> tuple[float, float, float]:
    return float(P[S.G_Z]), 0.0, float(P[S.DRY])


def _two_layer_numpy_advection(q: np.ndarray, dx: float, bc: tuple[int, int],
                               P: np.ndarray) -> tuple[np.ndarray, float]:
    return advection_rate(q, dx, bc, P[T.G_Z], P[T.DRY], P[T.R])


def _single_numpy_advection(q: np.ndarray, dx: float, bc: tuple[int, int],
                            P: np.ndarray) -> tuple[np.ndarray, float]:
    return advection_rate(q, dx, bc, P[S.G_Z], P[S.DRY], None)


TWO_LAYER = ModelKernels(
    fields=4, face=face_two_layer, fluctuations=fluctuations_two_layer,
    cell_jump=cell_jump_two_layer, sources=sources_two_layer,
    source_stage=source_stage_two_layer, predictor=predictor_two_layer,
    mol_sources=source_rate_two_layer, numpy_advection=_two_layer_numpy_advection,
    numpy_sources=source_rate_two_layer_np, constants=_two_layer_constants)
"""system (24) with closure (25): the fluctuations of :mod:`.pvm`, the source stages
(31)-(34) of :mod:`.source_stage`"""

SINGLE_LAYER = ModelKernels(
    fields=2, face=face_single, fluctuations=fluctuations_single,
    cell_jump=cell_jump_single, sources=sources_single, source_stage=source_stage_single,
    predictor=predictor_single, mol_sources=source_rate_single,
    numpy_advection=_single_numpy_advection, numpy_sources=source_rate_single_np,
    constants=_single_constants)
"""the Savage-Hutter-type layer with implicit Coulomb friction"""

TWO_LAYER_LAWS = dataclasses.replace(
    TWO_LAYER, sources=sources_two_layer_law, source_stage=source_stage_two_layer_law,
    predictor=predictor_two_layer_law)
""":data:`TWO_LAYER` with a rate-dependent basal law (:mod:`.law_stage`); the
method-of-lines rates read the law's code themselves"""

SINGLE_LAYER_LAWS = dataclasses.replace(
    SINGLE_LAYER, sources=sources_single_law, source_stage=source_stage_single_law,
    predictor=predictor_single_law)
""":data:`SINGLE_LAYER` with a rate-dependent basal law (:mod:`.law_stage`)"""
