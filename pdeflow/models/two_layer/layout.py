"""Parameter vector of the two-layer model (:class:`pdeflow.models.TwoLayerGranular`).

Starts with the header of :mod:`pdeflow.numerics.layout`; choices are codes from it.
"""

from ...numerics.layout import G_X, G_Z, N_HEADER, N_LAW

__all__ = ["G_Z", "G_X"]

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
