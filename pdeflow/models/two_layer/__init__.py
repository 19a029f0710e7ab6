"""The two-layer model of the paper (system (24), closure (25)), all of it in this package.

:mod:`.model` (parameters, the py-pde class, the equation system and its registration),
:mod:`.layout` (its parameter vector), :mod:`.flux` (face states, path-conservative
fluctuations, wave-speed bounds), :mod:`.sources` (the source stages (31)-(34)) with
:mod:`.exchange` (closure (25), implicit friction (32)), :mod:`.friction` (F_extra
(33)-(34)) and :mod:`.hyperbolicity`, :mod:`.laws` (the rate-dependent basal laws),
:mod:`.rates` (the method-of-lines rate), :mod:`.kernels` (the bundles the scheme takes).
"""

from .model import SYSTEM, TwoLayerGranular, TwoLayerParameters

__all__ = ["SYSTEM", "TwoLayerGranular", "TwoLayerParameters"]
