"""pdeflow: depth-averaged models of dry granular avalanches and dam-break flows.

Built on py-pde: the models are ``PDEBase`` subclasses, the paper's scheme is the
py-pde solver ``"fv-split"`` (registered on import).
"""

from . import early_signals

early_signals.install()  # the program only: a Ctrl-C during the imports below is kept

from .models import (  # noqa: E402
    SingleLayerGranular,
    SingleLayerParameters,
    TwoLayerGranular,
    TwoLayerParameters,
)
from .numerics.scheme import Scheme  # noqa: E402
from .solvers import FVSplitSolver, SimulationBlowUp  # noqa: E402

__version__ = "0.1.0"

__all__ = [
    "FVSplitSolver",
    "Scheme",
    "SimulationBlowUp",
    "SingleLayerGranular",
    "SingleLayerParameters",
    "TwoLayerGranular",
    "TwoLayerParameters",
    "__version__",
]
