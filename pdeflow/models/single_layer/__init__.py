"""The single-layer Coulomb baseline, all of it in this package.

:mod:`.model` (parameters, the py-pde class, the equation system and its registration),
:mod:`.layout` (its parameter vector), :mod:`.flux` (face states, fluctuations, MUSCL
cell jump), :mod:`.sources` (the implicit friction stage, also with a rate-dependent
basal law), :mod:`.rates` (the method-of-lines rate), :mod:`.kernels` (the bundles the
scheme takes); on a 2D grid :mod:`.two_d` (face states, fluctuations, MUSCL cell jump
along an axis) and :mod:`.sources_2d` (gravity along x, vector basal friction, the
method-of-lines source rate).
"""

from .model import SYSTEM, SingleLayerGranular, SingleLayerParameters

__all__ = ["SYSTEM", "SingleLayerGranular", "SingleLayerParameters"]
