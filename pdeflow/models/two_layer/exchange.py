r"""Source terms (26)-(27): mass exchange with closure (25), and implicit friction (32).

All quantities are kinematic (divided by rho2, see :mod:`pdeflow.numerics.layout`);
r = rho1/rho2, g = g_z, layer 1 = upper, layer 2 = lower, du = u1 - u2.

Closure (25)
------------
Interface shear stresses from the upper side (22) and the lower side (23), with the
hydrostatic interface pressure -t_zz = rho1 g h1 from (20)-(21):

.. math::  t_1/\rho_2 = \mathrm{sgn}(du)\,[k\, r g h_1 \tan\varphi_{int} + c\, du^2],\qquad
           t_2/\rho_2 = \mathrm{sgn}(du)\, r g h_1 \tan\varphi_{int},

.. math::  M/\rho_2 = \frac{t_1 - t_2}{\rho_2\, du}
           = \frac{c\, du^2 - (1-k)\, r g h_1 \tan\varphi_{int}}{\max(|du|, du_{reg})}.

M > 0 erodes the lower layer into the upper one, M < 0 deposits. du_reg = 0 is the paper's
closure, singular at du = 0 (docs/model.md, convergence.md); du_reg > 0 bounds the rate.
The *equilibrium depth* at which M vanishes for the current du is
h1_eq = c du^2 / ((1 - k) r g tan(phi_int)).

Relaxed closure (``exchange_closure = "relaxed"``): the exchange can be no faster than a
relaxation towards h1_eq on the flow's own time scale tau = tau_star sqrt(H / g_z)
(H = h1 + h2): over a step the depth change is the smaller of the paper's explicit
change and the exact relaxation (h1_eq - h1)(1 - exp(-dt/tau)). Where the layers shear
(|du| not small) the paper's rate is the slower one and is used unchanged; as du -> 0 the
rate stays bounded by h1/tau instead of diverging, so the deposited volume no longer
depends on the time step and hence on dx.

Exchange stage (31)
-------------------
h1 += dt M/rho1 and h2 -= dt M/rho2, with M limited so that h1 neither crosses h1_eq
nor goes negative and h2 stays non-negative; an upper layer left thinner than
``film`` is deposited whole, in erosion as in deposition (a film of a few grains is no
flowing layer, and left alone it can sit at h1_eq and creep for ever).

The exchanged mass carries the velocity of the layer it leaves (upwind): u1 when the
upper layer deposits, u2 when it erodes. Through (25) the upper layer's momentum
source of (27) can be written either way, u1 M - t1 = u2 M - (t1 - M du), so the
friction stage (32) of an eroding cell uses the interface stress t1 - M du with the
applied (limited) exchange M = phi M_25, 0 < phi <= 1:

.. math::  t_1 - M\,du = \phi\, t_2 + (1 - \phi)\, t_1,

i.e. (22) with k -> k + phi (1 - k) and c -> (1 - phi) c: the same convex friction law,
solved exactly by :func:`friction_two_layer`. Carrying u1 when eroding made a lower
layer held by basal friction pay the eroded mass's acceleration with explicit du while
the stress t1 came back at the implicit (braked) du; the difference created momentum,
and thin fast films eroded and slid for ever at large c (docs/model.md, "Coming to
rest when the upper layer erodes"). Either way rho1 h1 u1 + rho2 h2 u2 is conserved,
even when M is limited.

Implicit friction (32)
----------------------
With depths frozen, backward Euler for the momentum sources reads, with masses
m1 = r h1, m2 = h2 and b = u + dt g_x (after advection and exchange),

.. math::  m_1 (u_1 - b_1) + \Delta t\, F_{12} = 0,\qquad
           m_2 (u_2 - b_2) - \Delta t\, F_{12} + \Delta t\, F_B = 0,

.. math::  F_{12} \in K\,\mathrm{Sgn}(u_1 - u_2) + C (u_1-u_2)|u_1-u_2|,\qquad
           F_B \in B\,\mathrm{Sgn}(u_2),

K = k r g h1 tan(phi_int), C = c, B = g (r h1 + h2) tan(phi_B), Sgn set-valued at 0.
These are the optimality conditions of a strictly convex function of (u1, u2), so the
solution is unique; it is found in closed form by deciding first whether the lower
layer sticks (u2 = 0), then whether the layers lock (u1 = u2). A layer therefore stops
in finite time and stays stopped (no chattering of sgn(du)).

Where the lower layer is absent (h2 <= dry) the bed acts as a lower layer at rest: the
upper layer feels the interface law (22) against u2 = 0 and deposits onto the bed by
the same closure. Where the upper layer is absent the lower layer is a single Coulomb
layer with basal angle phi_B.
"""

from __future__ import annotations

import math

from ...numerics.compiled import cached
from ...numerics.implicit import drag_root


@cached
def _sign(x: float) -> float:
    if x > 0.0:
        return 1.0
    if x < 0.0:
        return -1.0
    return 0.0


@cached(inline="always")
def _sliding(p, b1, m1, mt, mu, Kdt, Cdt):
    """(d, u2) [m/s] of :func:`friction_two_layer` with the lower layer sliding, given
    the total momentum after basal friction ``p`` = m1 b1 + m2 b2 - Bdt s2 [m^2/s]:
    the relative velocity d = u1 - u2 solves mu d + Cdt d|d| + Kdt Sgn(d) = rel with
    rel = m1 (b1 - p/mt), and u2 = (p - m1 d)/mt."""
    rel = m1 * (b1 - p / mt)  # = mu (b1 - u_mean) : drive of the relative velocity
    d = _sign(rel) * drag_root(abs(rel) - Kdt, mu, Cdt)
    return d, (p - m1 * d) / mt


@cached
def friction_two_layer(b1, b2, m1, m2, Kdt, Cdt, Bdt):
    """Solve the coupled implicit friction step for (u1, u2); see module docstring.

    ``b1, b2`` velocities before friction [m/s]; ``m1 = r h1``, ``m2 = h2`` [m];
    ``Kdt = dt K``, ``Cdt = dt C``, ``Bdt = dt B`` [m^2/s] (C dt in [m]).

    The sliding solutions for both directions s2 = +-1 of the lower layer
    (p = m1 b1 + m2 b2 - Bdt s2) are computed before the stuck test decides between
    them and the stuck solution: they do not depend on it, so the three chains of
    divisions and square roots run side by side instead of one after the other.
    """
    mt = m1 + m2
    mu = m1 * m2 / mt
    p0 = m1 * b1 + m2 * b2
    # 2) lower layer slides in direction s2: total momentum after basal friction
    df, u2f = _sliding(p0 - Bdt, b1, m1, mt, mu, Kdt, Cdt)  # s2 = +1
    db, u2b = _sliding(p0 + Bdt, b1, m1, mt, mu, Kdt, Cdt)  # s2 = -1
    # 1) try the lower layer stuck: the upper layer slides over a fixed surface
    u1 = _sign(b1) * drag_root(m1 * abs(b1) - Kdt, m1, Cdt)
    push = m2 * b2 + m1 * (b1 - u1)  # force the stuck lower layer must resist, x dt
    if abs(push) <= Bdt:
        return u1, 0.0
    # the lower layer slides the way it is pushed; u2 of the other sign is round-off at
    # the stick/slip boundary
    if push > 0.0:
        return (df, 0.0) if u2f < 0.0 else (u2f + df, u2f)
    return (db, 0.0) if u2b > 0.0 else (u2b + db, u2b)


@cached
def closure_rate(h1: float, du: float, r: float, g: float, tan_int: float, k: float,
                 c: float, du_reg: float) -> float:
    """Kinematic mass flux M/rho2 [m/s] of closure (25); -inf at du = 0 if du_reg = 0."""
    num = c * du * du - (1.0 - k) * r * g * h1 * tan_int
    den = max(abs(du), du_reg)
    if den > 0.0:
        return num / den
    if num < 0.0:
        return -math.inf
    return 0.0


@cached
def relaxed_rate(m: float, h1: float, h2: float, du: float, r: float, g: float,
                 tan_int: float, k: float, c: float, tau: float) -> float:
    """Rate form of the relaxed closure: the kinematic mass flux ``m`` = M/rho2 [m/s]
    of (25), bounded by the relaxation towards h1_eq on the time scale ``tau`` [s]
    (the dt -> 0 limit of the relaxed exchange stage of :func:`exchange_step`):
    deposition no faster than r (h1 - h1_eq)/tau, erosion no faster than
    r (min(h1_eq, h1 + h2/r) - h1)/tau."""
    denom = (1.0 - k) * r * g * tan_int
    h1_eq = c * du * du / denom if denom > 0.0 else math.inf
    if m < 0.0:
        return max(m, r * (min(h1_eq, h1) - h1) / tau)
    if m > 0.0:
        return min(m, max(r * (min(h1_eq, h1 + h2 / r) - h1) / tau, 0.0))
    return m


@cached
def exchange_step(h1: float, h2: float, du: float, dt: float, r: float, g: float,
                  tan_int: float, k: float, c: float, du_reg: float, film: float,
                  tau: float) -> tuple[float, float]:
    """Change of the upper-layer depth [m] in the limited exchange stage (31), and the
    unlimited explicit change of the closure, rate dt / r [m] (their ratio is the phi of
    the erosion stress above).

    Negative changes deposit upper-layer material into the lower layer (whose depth
    changes by -r times the first value). ``tau`` [s] > 0 selects the *relaxed*
    closure: the change is the smaller of the paper's explicit step and the exactly
    integrated relaxation towards h1_eq with time scale tau,
    (h1_eq - h1)(1 - exp(-dt/tau)); ``tau`` = 0 is the paper's closure.
    """
    if h1 <= 0.0:
        return 0.0, 0.0
    rate = closure_rate(h1, du, r, g, tan_int, k, c, du_reg)
    denom = (1.0 - k) * r * g * tan_int
    h1_eq = c * du * du / denom if denom > 0.0 else math.inf
    dh1 = 0.0
    if rate < 0.0:
        dh1 = max(rate * dt / r, -(h1 - min(h1_eq, h1)))
        if tau > 0.0:
            relax = (h1 - min(h1_eq, h1)) * (1.0 - math.exp(-dt / tau))
            dh1 = max(dh1, -relax)
    elif rate > 0.0:
        dh1 = max(min(rate * dt / r, h1_eq - h1, h2 / r), 0.0)
        if tau > 0.0:
            relax = (min(h1_eq, h1 + h2 / r) - h1) * (1.0 - math.exp(-dt / tau))
            dh1 = min(dh1, max(relax, 0.0))
    if h1 + dh1 < film:
        # a film thinner than a few grains is no flowing layer: deposit it whole,
        # whatever the closure says (otherwise it can sit at h1_eq and creep forever)
        dh1 = -h1
    return dh1, rate * dt / r
