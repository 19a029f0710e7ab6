"""Parameter vector of the two-layer model (:class:`pdeflow.models.TwoLayerGranular`).

Starts with the header of :mod:`pdeflow.numerics.layout`; choices are codes from it.
"""

from ...numerics.layout import G_X, G_Y, G_Z, MODEL_SLOTS, N_HEADER, N_LAW

__all__ = ["G_Z", "G_X", "G_Y"]

R = N_HEADER  #: density ratio rho1/rho2 [-]
TAN_INT = N_HEADER + 1  #: tan(phi_int), internal friction at the interface [-]
TAN_B = N_HEADER + 2  #: tan(phi_B), basal friction of the lower layer [-]
K = N_HEADER + 3  #: friction reduction k of the upper side of the interface [-]
C = N_HEADER + 4  #: collisional coefficient c of eq. (17) [-]
W = N_HEADER + 5  #: tolerance in du of the hyperbolicity restoration (34) [m/s]
DRY = N_HEADER + 6  #: dry tolerance: a layer thinner than this has zero velocity [m]
FILM = N_HEADER + 7  #: upper-layer films thinner than this are deposited whole [m]
DU_REG = N_HEADER + 8  #: lower bound of |u1 - u2| in the closure denominator (0: paper) [m/s]
HYPERBOLICITY = N_HEADER + 9  #: restoration mode, layout.HYPERBOLICITY_* [code]
SLOW_U = N_HEADER + 10  #: speed below which a layer counts as "practically at rest" [m/s]
SLOW_H = N_HEADER + 11  #: depth above which the practical rest test looks at a cell [m]
MOL_EPS = N_HEADER + 12  #: velocity scale regularising sgn(u) in the method-of-lines rate [m/s]
CLOSURE = N_HEADER + 13  #: exchange closure, layout.CLOSURE_* [code]
TAU_STAR = N_HEADER + 14  #: relaxed closure: tau = TAU_STAR sqrt(H/g_z) [-]
LAW = N_HEADER + 15  #: start of the basal friction law's block (offsets layout.LAW_*)
SIZE = LAW + N_LAW

# --- the model's slots of the diagnostics vector (pdeflow.numerics.layout.MODEL_SLOTS) --
D_MOVE_UPPER = MODEL_SLOTS[0]  #: last time any upper-layer cell moved [s]
D_MOVE_LOWER = MODEL_SLOTS[1]  #: last time any lower-layer cell moved [s]
D_FAST_UPPER = MODEL_SLOTS[2]  #: last time |u1| >= SLOW_U somewhere with h1 > SLOW_H [s]
D_FAST_LOWER = MODEL_SLOTS[3]  #: same for the lower layer [s]
D_FEXTRA_MAX = MODEL_SLOTS[4]  #: largest F_extra/rho1 applied so far [m^2/s^2]
D_FEXTRA_CELL = MODEL_SLOTS[5]  #: cell index where it occurred
D_FEXTRA_TIME = MODEL_SLOTS[6]  #: time at which it occurred [s]
D_DEPOSITED = MODEL_SLOTS[7]  #: cumulative upper -> lower exchange, as upper-layer depth x dx [m]
D_ERODED = MODEL_SLOTS[8]  #: cumulative lower -> upper exchange, as upper-layer depth x dx [m]
D_HYP_EVENTS = MODEL_SLOTS[9]  #: number of cell-steps in which hyperbolicity was restored
D_HYP_BISECTIONS = MODEL_SLOTS[10]  #: restorations that needed the bisection fallback
DIAGNOSTICS = {
    "last_move_upper": D_MOVE_UPPER, "last_move_lower": D_MOVE_LOWER,
    "last_fast_upper": D_FAST_UPPER, "last_fast_lower": D_FAST_LOWER,
    "fextra_max": D_FEXTRA_MAX, "fextra_cell": D_FEXTRA_CELL, "fextra_time": D_FEXTRA_TIME,
    "deposited": D_DEPOSITED, "eroded": D_ERODED, "hyperbolicity_events": D_HYP_EVENTS,
    "hyperbolicity_bisections": D_HYP_BISECTIONS}
"""name -> slot, as :class:`pdeflow.solvers.diagnostics.SplitDiagnostics` reads them (the
exchanged depths ``deposited``/``eroded`` summed over cells [m]; times [s])"""
