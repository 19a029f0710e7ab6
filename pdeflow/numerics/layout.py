"""Index layout of the flat arrays the kernels share, and the codes of named choices.

Numba kernels receive the physical and numerical parameters as one float64 array, so
that a single compiled kernel (cached on disk) serves every parameter set and grid of
a sweep. Each model has its own parameter layout in its package
(:mod:`pdeflow.models.two_layer.layout`, :mod:`pdeflow.models.single_layer.layout`);
every layout starts with the header below, which the model-independent kernels (the
stepping loop) read. The model classes in
:mod:`pdeflow.models` fill these arrays; nothing else indexes them by number.

All stresses and mass fluxes inside the kernels are *kinematic*, i.e. divided by the
lower-layer density rho2: a momentum exchange F [Pa] appears as F/rho2 [m^2/s^2] and a
mass flux M [kg m^-2 s^-1] as M/rho2 [m/s]. Only the density ratio r = rho1/rho2 enters.
"""

# --- header of every model's parameter vector -----------------------------------------
G_Z = 0  #: gravity normal to the bed, g cos(theta) [m/s^2]
G_X = 1  #: gravity along the bed in x, g sin(theta) cos(azimuth) [m/s^2] (1D: g sin(theta))
G_Y = 2  #: gravity along the bed in y, g sin(theta) sin(azimuth) [m/s^2] (1D: 0, unread)
N_HEADER = 3

# --- diagnostics vector (post-step data of the splitting hook) -------------------------
# The scheme's slots; the others below N_DIAG (MODEL_SLOTS) are the model's own, named
# in its layout (e.g. pdeflow.models.two_layer.layout.D_MOVE_UPPER) and read by name
# through its system (pdeflow.systems.EquationSystem.diagnostics).
D_DT = 0  #: time step of the step just taken; 0 => the hook only cleans up [s]
D_T = 1  #: simulation time at the end of the last step [s]
D_CHANGED = 12  #: 1 if the last source stage changed any depth or momentum
D_STEPS = 13  #: number of source stages applied
D_FLUX_FALLBACKS = 14  #: steps redone with HLL because the IFCP step was not positive
D_BAD_STEPS = 16  #: steps of a generic py-pde solver that left a non-finite value or a depth
#: below -1e-12 m, before the post-step hook clipped it (models.base.make_post_step_hook)
D_RETRIES = 17  #: steps rejected (a depth would turn negative) and retried with dt / 2
D_RESUME = 18  #: 1 if D_LIVE_LO..D_LIVE_HI are the live cells of the state the fv-split
#: loop left (the next call goes on from them; pdeflow.numerics.resting), 2 the same after
#: a call whose last step reached its pause (its backup holds the state before it), else 0
D_LIVE_LO = 19  #: first live cell after the loop's last step
D_LIVE_HI = 20  #: last live cell after the loop's last step
MODEL_SLOTS = (2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 15)
"""the slots a model's source stage books in (its layout names them; saved along with
the scheme's when a step is retried)"""
N_DIAG = 21  #: the model's per-cell diagnostic (F_extra/rho1 of the last step) follows

# --- boundary conditions ---------------------------------------------------------------
BC_WALL = 0
BC_OPEN = 1
BOUNDARIES = {"wall": BC_WALL, "open": BC_OPEN}


def sides(codes: tuple[int, ...]) -> int:
    """One side's boundary codes of every axis of a grid as the one int the kernels take:
    axis a's code in bit a (BC_* are 0 and 1), so that a 1D grid's is its code."""
    return sum(int(code) << a for a, code in enumerate(codes))

# --- interface fluxes, reconstructions, limiters ---------------------------------------
FLUX_HLL = 0
FLUX_RUSANOV = 1
FLUX_IFCP = 2
FLUXES = {"hll": FLUX_HLL, "rusanov": FLUX_RUSANOV, "ifcp": FLUX_IFCP}
RECONSTRUCTIONS = {"first-order": 1, "muscl": 2}  #: name -> order of accuracy
LIMITER_MINMOD = 0
LIMITER_MC = 1
LIMITERS = {"minmod": LIMITER_MINMOD, "mc": LIMITER_MC}

# --- two-layer choices (stored as codes in the two-layer parameter vector) -------------
CLOSURE_PAPER = 0  #: closure (25) as published
CLOSURE_RELAXED = 1  #: (25) bounded by the relaxation towards the equilibrium depth
CLOSURE_NONE = 2  #: no mass exchange (two immiscible layers)
CLOSURES = {"paper": CLOSURE_PAPER, "relaxed": CLOSURE_RELAXED, "none": CLOSURE_NONE}
HYPERBOLICITY_NONE = 0  #: no restoration
HYPERBOLICITY_EXACT = 1  #: the paper's: the smallest F_extra that makes the spectrum real
HYPERBOLICITY_BOUND = 2  #: F_L, a bound on the exchange that suffices
HYPERBOLICITY_MODES = {"none": HYPERBOLICITY_NONE, "exact": HYPERBOLICITY_EXACT,
                       "bound": HYPERBOLICITY_BOUND}

# --- basal friction laws (pdeflow.numerics.rheology) -----------------------------------
# The law's block of a model's parameter vector: offsets from the model's LAW index. A
# law is chosen when its kernels are compiled (pdeflow.numerics.rheology.BasalLaw), not
# by a code in the vector; the block holds its constants. The shipped rate-dependent laws
# are written mu(h, s) = mu1 + dmu s / (s0(h) + s) (+ a Voellmy drag) for a speed s > 0,
# with s0(h) = S0 h^(3/2), and use the offsets below; another law may use the block as
# it likes, but for LAW_DRAG, the quadratic drag every law's deceleration adds.
LAW_MU1 = 0  #: friction coefficient as s -> 0 on the flowing branch (mu1, mu_s, mu) [-]
LAW_DMU = 1  #: mu2 - mu1 [-] (0 for Voellmy)
LAW_S0 = 2  #: s0(h) / h^(3/2): speed at which the rate part is half [m^-1/2 s^-1]
LAW_INV_L = 3  #: Pouliquen: 1/L [1/m]; 0 for the other laws
LAW_BETA_G = 4  #: Pouliquen: beta sqrt(g_z), the Fr = beta plateau edge / sqrt(h) [m^1/2/s]
LAW_DRAG = 5  #: Voellmy: g / xi [1/m]; 0 for the other laws
N_LAW = 6

# --- geometry of the grid (pdeflow.numerics.geometry) -----------------------------------
GEOMETRY_PLANAR = 0  #: a 1D Cartesian grid: the planar slope, per unit width
GEOMETRY_AXISYMMETRIC = 1  #: py-pde's PolarSymGrid: radial flow on a horizontal plane
GEOMETRIES = {"planar": GEOMETRY_PLANAR, "axisymmetric": GEOMETRY_AXISYMMETRIC}
GEOMETRY_PLANAR_2D = 2  #: a 2D Cartesian grid (the face loop only: no case file selects it yet)
GEOMETRY_TERRAIN_2D = 3  #: a 2D Cartesian grid over a bed z_b(x, y) (metric rows M_BED)
GRID_GEOMETRIES = {**GEOMETRIES, "planar-2d": GEOMETRY_PLANAR_2D}
"""every geometry the kernels know (:data:`GEOMETRIES`: those a case file may name)"""
M_LEFT = 0  #: metric row: A_{i-1/2} / V_{i-1}, face i - 1/2's weight in cell i - 1 [1/m]
M_RIGHT = 1  #: metric row: A_{i-1/2} / V_i, face i - 1/2's weight in cell i [1/m]
M_AREA_CHANGE = 2  #: metric row: (A_{i+1/2} - A_{i-1/2}) / V_i [1/m] (n entries)
M_AXES = 3  #: metric row: per axis a, [3a] its stride in the flattened cell index, [3a + 1]
#: its number of cells, [3a + 2] its cell width [m] (read by the 2D kernels only)
N_METRIC = 4
M_BED = N_METRIC  #: over a bed, 4 metric rows per cell: the bed [m] at the middle of its
#: low and high faces along x, then along y (pdeflow.numerics.geometry.face_beds)
N_BED = 4
