"""The part of a model's kernel parameter vector that every model shares.

Each model's parameter dataclass fills its own vector (its layout in its package); the
header it starts with (:mod:`pdeflow.numerics.layout`: ``G_Z``, ``G_X``) comes from the
parameters every model has (:class:`pdeflow.models.base.SharedParameters`), written
here once.
"""

from __future__ import annotations

import math

import numpy as np

from ..numerics import layout as L
from .base import SharedParameters


def parameter_vector(p: SharedParameters, size: int) -> np.ndarray:
    """A model's kernel parameter vector of ``size`` floats: the shared header (gravity
    normal to the bed g cos(theta) and along it g sin(theta) [m/s^2]) and zeros for the
    model to fill."""
    th = math.radians(p.theta_deg)
    P = np.zeros(size)
    P[L.G_Z] = p.g * math.cos(th)
    P[L.G_X] = p.g * math.sin(th)
    return P
