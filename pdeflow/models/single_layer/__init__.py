"""The single-layer Coulomb baseline, all of it in this package.

:mod:`.model` (parameters, the py-pde class, the equation system and its registration),
:mod:`.layout` (its parameter vector), :mod:`.flux` (face states, fluctuations, MUSCL
cell jump), :mod:`.sources` (the implicit friction stage, also with a rate-dependent
basal law), :mod:`.rates` (the method-of-lines rate), :mod:`.kernels` (the bundles the
scheme takes).
"""

from .model import SYSTEM, SingleLayerGranular, SingleLayerParameters

__all__ = ["SYSTEM", "SingleLayerGranular", "SingleLayerParameters"]
