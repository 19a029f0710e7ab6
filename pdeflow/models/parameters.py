"""The part of a model's kernel parameter vector that every model shares.

Each model's parameter dataclass fills its own vector (its layout in its package); the
header it starts with (:mod:`pdeflow.numerics.layout`: ``G_Z``, ``G_X``, ``G_Y``) comes
from the parameters every model has (:class:`pdeflow.models.base.SharedParameters`),
written here once.
"""

from __future__ import annotations

import math

import numpy as np

from ..numerics import layout as L
from .base import SharedParameters

AXES = {0.0: (1.0, 0.0), 90.0: (0.0, 1.0), 180.0: (-1.0, 0.0), -90.0: (0.0, -1.0),
        -180.0: (-1.0, 0.0)}
"""(cos, sin) of the azimuths along the grid's axes [deg], exact: cos(pi/2) rounds to
6e-17, which would give a plane inclined along y a gravity component along x"""


def downslope(azimuth_deg: float) -> tuple[float, float]:
    """The unit vector (n_x, n_y) of the steepest descent at ``azimuth_deg`` [deg] from x
    towards y: exact along the axes (:data:`AXES`)."""
    if azimuth_deg in AXES:
        return AXES[azimuth_deg]
    a = math.radians(azimuth_deg)
    return math.cos(a), math.sin(a)


def parameter_vector(p: SharedParameters, size: int) -> np.ndarray:
    """A model's kernel parameter vector of ``size`` floats: the shared header (gravity
    normal to the bed g cos(theta), along it g sin(theta) (n_x, n_y), n the steepest
    descent at ``slope_azimuth_deg``, [m/s^2]) and zeros for the model to fill. At
    azimuth 0 (every 1D grid) the x component is g sin(theta) exactly, the y one 0."""
    th = math.radians(p.theta_deg)
    nx, ny = downslope(p.slope_azimuth_deg)
    P = np.zeros(size)
    P[L.G_Z] = p.g * math.cos(th)
    P[L.G_X] = p.g * math.sin(th) * nx
    P[L.G_Y] = p.g * math.sin(th) * ny
    return P
