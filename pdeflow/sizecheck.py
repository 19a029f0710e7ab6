"""Refusing runs that the machine cannot do (issue 28), before any work.

A run is refused (:class:`pdeflow.cases.CaseError`, exit 2, one line with the estimate)
if its estimated wall time exceeds :data:`MAX_RUN_SECONDS` or its estimated memory
:data:`MAX_MEMORY_FRACTION` of the machine's physical memory; ``--force`` runs it
anyway. Below these limits a long run is only announced (``checks.cost_warning``).
The estimates are those of :func:`pdeflow.checks.run_cost` (wall time at
``CELL_UPDATES_PER_S``, the slow end of the compiled loop: an estimate from above).
"""

from __future__ import annotations

from typing import Any

from .checks import _bytes, _duration, physical_memory, run_cost

MAX_RUN_SECONDS = 24 * 3600.0  #: estimated wall time above which a run is refused [s]
MAX_MEMORY_FRACTION = 0.5  #: estimated memory above this share of the machine's: refused


def size_problem(case: Any) -> str | None:
    """Why the costliest model of ``case`` is beyond the limits, or None."""
    have = physical_memory()
    for model in case.models:
        cost = run_cost(case, model)
        too_long = cost.seconds > MAX_RUN_SECONDS
        too_big = have is not None and cost.memory_bytes > MAX_MEMORY_FRACTION * have
        if too_long or too_big:
            limit = (f"above the limit of {_duration(MAX_RUN_SECONDS)}" if too_long else
                     f"above {MAX_MEMORY_FRACTION:.0%} of this machine's {_bytes(have)}")
            return (f"{model} on {cost.cells:,} cells (dx = {case.dx:.3g} m) is estimated "
                    f"at roughly {_duration(cost.seconds)} and {_bytes(cost.memory_bytes)} "
                    f"of memory, {limit}")
    return None


def check_size(case: Any, force: bool, remedy: str) -> None:
    """Raise :class:`~pdeflow.cases.CaseError` if ``case`` is beyond the limits and not
    ``force``; ``remedy`` names the option that makes it smaller (e.g. ``--set
    grid.dx=...``, ``--levels``)."""
    from .cases import CaseError

    problem = None if force else size_problem(case)
    if problem:
        raise CaseError(f"{case.name}: {problem}; {remedy}, or --force to run it anyway")
