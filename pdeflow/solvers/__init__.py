"""py-pde solvers provided by pdeflow (importing registers them with py-pde)."""

from .fv_split import FVSplitSolver, SimulationBlowUp

__all__ = ["FVSplitSolver", "SimulationBlowUp"]
