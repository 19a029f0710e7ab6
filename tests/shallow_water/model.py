"""Frictionless shallow water: d_t h + d_x(hu) = 0, d_t(hu) + d_x(hu^2 + g h^2/2) = g_x h
(parameters, py-pde class, kernel bundle, equation system; not registered here)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pdeflow import systems
from pdeflow.models.base import GranularPDE, SharedParameters, stop_time
from pdeflow.models.parameters import parameter_vector
from pdeflow.models.single_layer import flux as saint_venant
from pdeflow.models.single_layer.rates import fluctuations_np
from pdeflow.numerics.model_kernels import ModelKernels
from pdeflow.numerics.vectorized import advection_rate

from . import layout as W
from .sources import sw_mol_sources, sw_numpy_sources, sw_predictor, sw_source_stage, sw_sources

NAME = "shallow_water"


@dataclass
class ShallowWaterParameters(SharedParameters):
    """Frictionless shallow water: gravity, slope and the shared tolerances only."""

    kind = "shallow-water"

    def to_array(self) -> np.ndarray:
        P = parameter_vector(self, W.SIZE)
        P[W.DRY] = self.dry_tolerance
        return P


KERNELS = ModelKernels(
    fields=2, face=saint_venant.face, fluctuations=saint_venant.fluctuations,
    cell_jump=saint_venant.cell_jump, sources=sw_sources, source_stage=sw_source_stage,
    predictor=sw_predictor, mol_sources=sw_mol_sources,
    numpy_advection=lambda q, dx, bc, P: advection_rate(q, dx, bc, fluctuations_np, P[W.G_Z],
                                                        P[W.DRY]),
    numpy_sources=sw_numpy_sources,
    constants=lambda P: (float(P[W.G_Z]), 0.0, float(P[W.DRY])))


class ShallowWater(GranularPDE):
    """Frictionless shallow water as a py-pde PDE (state h, hu)."""

    parameters_class = ShallowWaterParameters


SYSTEM = systems.EquationSystem(
    name=NAME, label="shallow water", adjective="shallow-water",
    layers=(systems.Layer("h", "hu", "u", "water", "single"),),
    parameters_class=ShallowWaterParameters, pde_class=ShallowWater, kernels=KERNELS,
    diagnostics=W.DIAGNOSTICS, densities=lambda p: (1.0,),
    layer_depths=lambda h, x, ini, p: (h,),
    summarize=lambda diag, tf, at_rest, x, d, metric: {
        "stop_time": stop_time(diag.last_move, tf, at_rest), "max_fextra_over_rho1": 0.0},
    bytes_per_cell=180)
ShallowWater.system = SYSTEM
