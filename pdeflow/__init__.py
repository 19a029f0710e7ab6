"""pdeflow: depth-averaged models of dry granular avalanches and dam-break flows.

Built on py-pde: the models are ``PDEBase`` subclasses, the paper's scheme is the
py-pde solver ``"fv-split"`` (registered on import).
"""

from .models import (
    SingleLayerGranular,
    SingleLayerParameters,
    TwoLayerGranular,
    TwoLayerParameters,
)
from .solvers import FVSplitSolver, SimulationBlowUp

__version__ = "0.1.0"

__all__ = [
    "FVSplitSolver",
    "SimulationBlowUp",
    "SingleLayerGranular",
    "SingleLayerParameters",
    "TwoLayerGranular",
    "TwoLayerParameters",
    "__version__",
]
