"""The single layer's kernels as :class:`~pdeflow.numerics.model_kernels.ModelKernels`
bundles: what the model-free stepping loop, advection stage and method-of-lines rate
take of it, one bundle per basal law (:func:`kernels`; on a 2D grid :func:`kernels_2d`)."""

from __future__ import annotations

import functools

import numpy as np

from ...numerics.model_kernels import ModelKernels
from ...numerics.rheology import BasalLaw
from ...numerics.vectorized import advection_rate
from . import layout as S
from . import two_d
from .flux import cell_jump, face, fluctuations
from .rates import fluctuations_np, source_rate, source_rate_np
from .sources import stage_kernels
from .sources_2d import fold_single_2d, source_rate_2d, stage_kernels_2d
from .terrain import reconstruct_bed


def _constants(P: np.ndarray) -> tuple[float, float, float]:
    return float(P[S.G_Z]), 0.0, float(P[S.DRY])


def _numpy_advection(q: np.ndarray, dx: float, bc: tuple[int, int],
                     P: np.ndarray) -> tuple[np.ndarray, float]:
    return advection_rate(q, dx, bc, fluctuations_np, P[S.G_Z], P[S.DRY])


@functools.cache
def kernels(law: BasalLaw | None = None) -> ModelKernels:
    """The Savage-Hutter-type layer with the implicit basal friction of ``law`` (None:
    Coulomb's closed form)."""
    sources, source_stage, predictor = stage_kernels(law)
    return ModelKernels(
        fields=2, face=face, fluctuations=fluctuations, cell_jump=cell_jump,
        sources=sources, source_stage=source_stage, predictor=predictor,
        mol_sources=source_rate(law), numpy_advection=_numpy_advection,
        numpy_sources=functools.partial(source_rate_np, law=law), constants=_constants)


KERNELS = kernels()
"""the Savage-Hutter-type layer with implicit Coulomb friction"""


def _no_numpy_twin_2d(*args: object) -> None:
    raise NotImplementedError("the single layer's numpy twins are 1D only: on a 2D grid "
                              "use the numba backend")


@functools.cache
def kernels_2d(law: BasalLaw | None = None) -> ModelKernels:
    """:func:`kernels` on a 2D grid: state (h, hu, hv), the faces of both axes in their
    normal frames (:mod:`.two_d`), gravity along x and the vector basal friction of
    ``law`` (None: Coulomb's; :mod:`.sources_2d`), and over a bed :mod:`.terrain`. No
    numpy twins (NotImplementedError)."""
    sources, source_stage, predictor = stage_kernels_2d(law)
    return ModelKernels(
        fields=3, face=two_d.face, fluctuations=two_d.fluctuations,
        cell_jump=two_d.cell_jump, sources=sources, source_stage=source_stage,
        predictor=predictor, mol_sources=source_rate_2d(law),
        numpy_advection=_no_numpy_twin_2d, numpy_sources=_no_numpy_twin_2d,
        constants=_constants, fold=fold_single_2d, terrain=reconstruct_bed,
        layer_rows=3, rows=two_d.ROWS)
