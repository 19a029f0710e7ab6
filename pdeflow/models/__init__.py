"""Equation systems: each owns its parameters, state layout and kernels."""

from .single_layer import SingleLayerGranular, SingleLayerParameters
from .two_layer import TwoLayerGranular, TwoLayerParameters

__all__ = [
    "SingleLayerGranular",
    "SingleLayerParameters",
    "TwoLayerGranular",
    "TwoLayerParameters",
]
