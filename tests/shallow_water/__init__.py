"""Frictionless shallow water as a model package of its own: the recipe of
docs/architecture.md ("Adding a model") carried out outside pdeflow.

:mod:`.layout` (its parameter vector and diagnostics slots), :mod:`.sources` (its
kernels: the source stage; the flux is the single layer's Saint-Venant one, which is
what a one-layer model's flux is), :mod:`.model` (parameters, py-pde class, equation
system). Registering :data:`SYSTEM` (``pdeflow.systems.register(SYSTEM)``) is the one
line that makes pdeflow run it (tests/test_third_model.py).
"""

from .model import NAME, SYSTEM, ShallowWater, ShallowWaterParameters

__all__ = ["NAME", "SYSTEM", "ShallowWater", "ShallowWaterParameters"]
