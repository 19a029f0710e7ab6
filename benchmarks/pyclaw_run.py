"""The single-layer Coulomb collapse in PyClaw (Clawpack), for the speed comparison.

Optional: ``pip install clawpack`` builds Fortran Riemann solvers and needs gfortran
(``apt-get install gfortran``). :func:`available` says whether it can be imported; the
suite skips PyClaw cleanly when it cannot.

Set-up, as close to pdeflow's ``hll/first-order`` single layer as PyClaw allows:
Fortran HLLE Riemann solver (``shallow_hlle_1D``; Einfeldt speeds instead of Davis'),
first order (Godunov, no limiter), variable dt with ``cfl_desired`` = the CFL number,
left wall, right extrapolation, Godunov source splitting with the implicit set-valued
Coulomb friction in ``solver.step_source``. PyClaw cannot represent dry cells: the bed
carries a film of ``FILM`` = 1e-6 m (which friction holds at rest). PyClaw has no
stop-at-rest, so it runs to the time at which pdeflow found the collapse at rest.

Units: depths [m], dx [m], times [s], g [m/s^2], angles [deg].
"""

from __future__ import annotations

import math
import os
import tempfile
import time
from typing import Any

import numpy as np

FILM = 1e-6
"""depth of the film on dry cells [m] (PyClaw's solvers need h > 0)"""


NEEDS_CLAWPACK = "clawpack is not installed (pip install clawpack; needs gfortran)"
"""the one line said where PyClaw is needed and cannot be imported"""


def available(riemann_solver: str = "shallow_hlle_1D") -> bool:
    """True if ``clawpack.pyclaw`` and the Riemann solver ``riemann_solver`` (a module of
    ``clawpack.riemann``; by default the 1D HLLE shallow-water one) import.

    PyClaw's import opens a log file ``pyclaw.log`` in the working directory: it is
    imported from a temporary directory so that the file lands there.
    """
    cwd = os.getcwd()
    os.chdir(tempfile.mkdtemp(prefix="pyclaw-"))
    try:
        import importlib

        from clawpack import pyclaw, riemann  # noqa: F401
        importlib.import_module(f"clawpack.riemann.{riemann_solver}")
    except Exception:  # pragma: no cover - depends on the machine
        return False
    finally:
        os.chdir(cwd)
    return True


def first_order(solver: Any, cfl: float, cfl_max: float) -> None:
    """Set a PyClaw classic ``solver`` to first order (Godunov, no limiter), Fortran
    kernels, a variable time step aiming at Courant number ``cfl`` (steps above
    ``cfl_max`` are redone), no step limit."""
    from clawpack import pyclaw

    solver.kernel_language = "Fortran"
    solver.order = 1
    solver.limiters = pyclaw.limiters.tvd.minmod  # unused at order 1
    solver.cfl_desired = cfl
    solver.cfl_max = cfl_max
    solver.dt_variable = True
    solver.max_steps = 10**8


def run_controller(state: Any, domain: Any, solver: Any, t_end: float
                   ) -> tuple[float, np.ndarray, int]:
    """Run ``solver`` from ``state`` on ``domain`` to ``t_end`` [s] without output.

    Returns (wall time of ``controller.run()`` [s], the final ``q``, number of steps).
    """
    from clawpack import pyclaw

    claw = pyclaw.Controller()
    claw.solution = pyclaw.Solution(state, domain)
    claw.solver = solver
    claw.tfinal = t_end
    claw.num_output_times = 1
    claw.keep_copy = False
    claw.output_format = None
    claw.verbosity = 0
    w0 = time.perf_counter()
    status = claw.run()
    wall = time.perf_counter() - w0
    steps = int(status.get("numsteps", 0)) if isinstance(status, dict) else 0
    if not steps:
        steps = int(getattr(solver.status, "get", lambda *_: 0)("numsteps", 0) or 0)
    return wall, claw.solution.state.q.copy(), steps


def collapse(L0: float, H0: float, length: float, dx: float, t_end: float,
             phi_b_deg: float = 30.0, g: float = 9.81, cfl: float = 0.3
             ) -> tuple[float, np.ndarray, int]:
    """Column of length L0 and height H0 [m] against the left wall, run to ``t_end``.

    Returns (wall time of ``controller.run()`` [s], final depth [m], number of steps).
    """
    if not available():
        raise ImportError(NEEDS_CLAWPACK)
    from clawpack import pyclaw, riemann

    solver = pyclaw.ClawSolver1D(riemann.shallow_hlle_1D)
    first_order(solver, cfl, min(1.0, 1.5 * cfl))
    solver.bc_lower[0] = pyclaw.BC.wall
    solver.bc_upper[0] = pyclaw.BC.extrap
    solver.source_split = 1
    mu = g * math.tan(math.radians(phi_b_deg))

    def coulomb(solver, state, dt):  # noqa: ARG001 - PyClaw's signature
        q = state.q
        h = q[0]
        u = q[1] / h
        v = np.sign(u) * np.maximum(np.abs(u) - dt * mu, 0.0)
        q[1] = h * v

    solver.step_source = coulomb
    n = round(length / dx)
    x = pyclaw.Dimension(0.0, length, n, name="x")
    domain = pyclaw.Domain(x)
    state = pyclaw.State(domain, 2)
    state.problem_data["grav"] = g
    state.problem_data["dry_tolerance"] = 1e-3 * FILM
    state.problem_data["sea_level"] = 0.0
    xc = state.grid.x.centers
    state.q[0, :] = np.where(xc < L0, H0, FILM)
    state.q[1, :] = 0.0
    wall, q, steps = run_controller(state, domain, solver, t_end)
    return wall, q[0], steps
