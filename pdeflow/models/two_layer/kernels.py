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
from . import two_d
from .flux import cell_jump, face, fluctuations
from .rates import fluctuations_np, source_rate, source_rate_np
from .rates_2d import source_rate_2d
from .sources import stage_kernels
from .sources_2d import fold_two_layer_2d, stage_kernels_2d
from .terrain import reconstruct_bed


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


def _no_numpy_twin(*args: object) -> tuple[np.ndarray, float]:
    raise NotImplementedError("the two-layer 2D kernels have no numpy twin: use the "
                              "numba backend")


@functools.cache
def kernels_2d(law: BasalLaw | None = None, directions: str = "all") -> ModelKernels:
    """System (24) on a 2D CartesianGrid (x down the slope, y across; rows h1, h1u1,
    h1v1, h2, h2u2, h2v2): the face states, fluctuations and MUSCL cell jump of
    :mod:`.two_d`, the source stages of :mod:`.sources_2d` (hyperbolicity restored in
    ``directions`` 'all' or, as in 1D, along the 'flow') and the method-of-lines rate
    of :mod:`.rates_2d`, with the basal law ``law`` (None: the paper's Coulomb
    friction at the bed); over a bed the face values of :mod:`.terrain`."""
    sources, source_stage, predictor = stage_kernels_2d(law, directions)
    return ModelKernels(
        fields=6, face=two_d.face, fluctuations=two_d.fluctuations,
        cell_jump=two_d.cell_jump, sources=sources, source_stage=source_stage,
        predictor=predictor, mol_sources=source_rate_2d(law), numpy_advection=_no_numpy_twin,
        numpy_sources=_no_numpy_twin, constants=_constants, fold=fold_two_layer_2d,
        terrain=reconstruct_bed, layer_rows=two_d.LAYER_ROWS, rows=two_d.ROWS)


KERNELS = kernels()
"""the paper's system with Coulomb friction at the bed"""
