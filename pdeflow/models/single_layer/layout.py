"""Parameter vector of the single-layer model (:class:`pdeflow.models.SingleLayerGranular`).

Starts with the header of :mod:`pdeflow.numerics.layout`.
"""

from ...numerics.layout import G_X, G_Y, G_Z, MODEL_SLOTS, N_HEADER, N_LAW

__all__ = ["G_Z", "G_X", "G_Y"]

TAN_B = N_HEADER  #: tan(phi_B), basal friction [-]
DRY = N_HEADER + 1  #: dry tolerance [m]
SLOW_U = N_HEADER + 2  #: speed below which the layer counts as practically at rest [m/s]
SLOW_H = N_HEADER + 3  #: depth above which the practical rest test looks at a cell [m]
MOL_EPS = N_HEADER + 4  #: velocity scale regularising sgn(u) in the method-of-lines rate [m/s]
LAW = N_HEADER + 5  #: start of the basal friction law's block (offsets layout.LAW_*)
SIZE = LAW + N_LAW

# --- the model's slots of the diagnostics vector (pdeflow.numerics.layout.MODEL_SLOTS) --
D_MOVE = MODEL_SLOTS[0]  #: last time any cell moved [s]
D_FAST = MODEL_SLOTS[2]  #: last time |u| >= SLOW_U somewhere with h > SLOW_H [s]
DIAGNOSTICS = {"last_move": D_MOVE, "last_fast": D_FAST}
"""name -> slot, as :class:`pdeflow.solvers.diagnostics.SplitDiagnostics` reads them"""
