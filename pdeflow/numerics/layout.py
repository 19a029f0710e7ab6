"""Index layout of the flat parameter and diagnostics arrays shared by the kernels.

Numba kernels receive the physical and numerical parameters as one float64 array, so
that a single compiled kernel (cached on disk) serves every parameter set and grid of
a sweep. The model classes in :mod:`pdeflow.models` fill these arrays; nothing else
should index them by number.

All stresses and mass fluxes inside the kernels are *kinematic*, i.e. divided by the
lower-layer density rho2: a momentum exchange F [Pa] appears as F/rho2 [m^2/s^2] and a
mass flux M [kg m^-2 s^-1] as M/rho2 [m/s]. Only the density ratio r = rho1/rho2 enters.
"""

# --- two-layer parameter vector -------------------------------------------------------
G_Z = 0  #: gravity normal to the bed, g cos(theta) [m/s^2]
G_X = 1  #: gravity along the bed (down-slope positive), g sin(theta) [m/s^2]
R = 2  #: density ratio rho1/rho2 [-]
TAN_INT = 3  #: tan(phi_int), internal friction at the interface [-]
TAN_B = 4  #: tan(phi_B), basal friction of the lower layer [-]
K = 5  #: friction reduction k of the upper side of the interface [-]
C = 6  #: collisional coefficient c of eq. (17) [-]
W = 7  #: tolerance in du of the hyperbolicity restoration (paper: threshold of (34)) [m/s]
DRY = 8  #: dry tolerance: a layer thinner than this has zero velocity [m]
FILM = 9  #: upper-layer films thinner than this are deposited whole [m]
DU_REG = 10  #: lower bound of |u1 - u2| in the closure denominator (0: paper) [m/s]
HYPERBOLICITY = 11  #: 0 none, 1 exact inner eigenvalues (paper), 2 bound F_L
SLOW_U = 12  #: speed below which a layer counts as "practically at rest" [m/s]
SLOW_H = 13  #: depth above which the practical rest test looks at a cell [m]
MOL_EPS = 14  #: velocity scale regularising sgn(u) in the method-of-lines rate [m/s]
TAU_STAR = 15  #: relaxed closure tau = TAU_STAR sqrt(H/g_z); 0: paper's; < 0: no exchange
N_TWO_LAYER = 16

# --- single-layer parameter vector (first entries coincide with the two-layer one) -----
S_G_Z = 0
S_G_X = 1
S_TAN_B = 2
S_DRY = 3
S_SLOW_U = 4
S_SLOW_H = 5
S_MOL_EPS = 6
N_SINGLE_LAYER = 7

# --- diagnostics vector (post-step data of the splitting hook) -------------------------
D_DT = 0  #: time step of the step just taken; 0 => the hook only cleans up [s]
D_T = 1  #: simulation time at the end of the last step [s]
D_MOVE_UPPER = 2  #: last time any upper-layer (or the single layer) cell moved [s]
D_MOVE_LOWER = 3  #: last time any lower-layer cell moved [s]
D_FAST_UPPER = 4  #: last time |u1| >= SLOW_U somewhere with h1 > SLOW_H [s]
D_FAST_LOWER = 5  #: same for the lower layer [s]
D_FEXTRA_MAX = 6  #: largest F_extra/rho1 applied so far [m^2/s^2]
D_FEXTRA_CELL = 7  #: cell index where it occurred
D_FEXTRA_TIME = 8  #: time at which it occurred [s]
D_DEPOSITED = 9  #: cumulative upper -> lower exchange, as upper-layer depth x dx [m]
D_ERODED = 10  #: cumulative lower -> upper exchange, as upper-layer depth x dx [m]
D_HYP_EVENTS = 11  #: number of cell-steps in which hyperbolicity was restored
D_CHANGED = 12  #: 1 if the last source stage changed any depth or momentum
D_STEPS = 13  #: number of source stages applied
D_FLUX_FALLBACKS = 14  #: steps redone with HLL because the IFCP step was not positive
D_HYP_BISECTIONS = 15  #: restorations that needed the bisection fallback (see splitting)
D_BAD_STEPS = 16  #: steps of a generic py-pde solver that left a non-finite value or a depth
#: below -1e-12 m, before the post-step hook clipped it (models.base.make_post_step_hook)
D_RETRIES = 17  #: steps rejected (a depth would turn negative) and retried with dt / 2
N_DIAG = 18  #: the per-cell F_extra/rho1 of the last step follows at N_DIAG

# --- boundary conditions ---------------------------------------------------------------
BC_WALL = 0
BC_OPEN = 1

# --- interface fluxes, reconstructions, limiters, splittings ----------------------------
FLUX_HLL = 0
FLUX_RUSANOV = 1
FLUX_IFCP = 2
FLUXES = {"hll": FLUX_HLL, "rusanov": FLUX_RUSANOV, "ifcp": FLUX_IFCP}
LIMITER_MINMOD = 0
LIMITER_MC = 1
LIMITERS = {"minmod": LIMITER_MINMOD, "mc": LIMITER_MC}
