r"""Interface fluctuations of every flux in polynomial-viscosity (PVM) form.

All three fluxes (:mod:`~pdeflow.numerics.hll`, :mod:`~pdeflow.numerics.rusanov`,
:mod:`~pdeflow.numerics.ifcp`) are written as

.. math::  D^\mp = \tfrac12\,\bigl(\mathcal{A}\Delta q \mp Q(A)\,\Delta q\bigr),\qquad
           Q(A)\Delta q = \alpha_0 \Delta q + \alpha_1 \mathcal{A}\Delta q
                          + \alpha_2 A(\mathcal{A}\Delta q),

(Castro & Fernandez-Nieto 2012), where A Delta q is the path-conservative total jump
f(q_R) - f(q_L) + B_LR (see :mod:`~pdeflow.numerics.hll`) and A the pseudo-Jacobian at the
Roe-averaged state (needed by IFCP only). D^- + D^+ = A Delta q for every flux.

Layers at rest on both sides of a face (zero momentum) get no mass fluctuation and their
hydrostatic jump split by each side's own depth, whatever the flux (this is what keeps a
Coulomb heap below its friction angle exactly at rest).

Each model writes its fluctuations in this form with the coefficients of
:mod:`~pdeflow.numerics.hll`, :mod:`~pdeflow.numerics.rusanov` and
:mod:`~pdeflow.numerics.ifcp` (``fluctuations(flux)`` of the model's ``flux`` module, e.g.
:mod:`pdeflow.models.two_layer.flux`), compiled for one flux at a time; this module holds
what they share.
"""

from __future__ import annotations

import math

from .compiled import cached


@cached
def roe_velocity(hL: float, uL: float, hR: float, uR: float) -> float:
    """Roe-averaged velocity [m/s] of a layer between depths hL, hR [m] moving at uL, uR
    [m/s] (0 between two dry sides): IFCP's linearisation state."""
    sl = math.sqrt(max(hL, 0.0))
    sr = math.sqrt(max(hR, 0.0))
    if sl + sr <= 0.0:
        return 0.0
    return (sl * uL + sr * uR) / (sl + sr)
