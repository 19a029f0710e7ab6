"""Small builders shared by the tests."""

from __future__ import annotations

import contextlib
import dataclasses
import importlib
import os
import sys
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from pde import CartesianGrid

import pdeflow
from pdeflow.solvers.fv_split import split_stepper


def grid(n: int = 100, lo: float = 0.0, hi: float = 1.0) -> CartesianGrid:
    return CartesianGrid([[lo, hi]], n)


def step(eq, state, t_end: float, cfl: float = 0.3, stop_at_rest: bool = False,
         max_steps: int = 10**7, strang: bool = False):
    """Run the compiled fv-split loop directly; returns (q, t, steps, status, diag)."""
    q = state.data.copy()
    diag = eq.new_diagnostics(q.shape[1])
    metric = eq.metric(state.grid)
    scheme = dataclasses.replace(eq.scheme, splitting="strang" if strang else "lie")
    stepper = split_stepper(eq, metric, scheme)
    t, steps, status = stepper(q, 0.0, t_end, metric.dx, metric.array(), *eq.bc_codes,
                               eq.parameter_array(), cfl, diag, np.empty_like(q),
                               np.empty_like(q), np.empty((3, *q.shape)), max_steps,
                               stop_at_rest)
    return q, t, steps, status, diag


def two_layer_column(n: int = 140, length: float = 7.0, **params):
    """The paper's 5.1 initial state on an n-cell grid (both ends walls)."""
    g = grid(n, 0.0, length)
    x = g.axes_coords[0]
    eq = pdeflow.TwoLayerGranular(bc=("wall", "wall"), **params)
    h2 = np.where(x < 1, np.minimum(2.0, (1 - x) * np.tan(np.radians(60))), 0.0)
    h1 = np.where(x < 1, 2.0 - h2, 0.0)
    return eq, eq.make_state(g, h1=h1, h2=h2)


def ishigami_study(design: str, samples: int, seed: int, bound: float = 3,
                   delay: float | None = None, name: str | None = None) -> str:
    """The text of a study file of ``tests.studyfunctions:ishigami`` (quantity
    ``y``) over x1, x2, x3 uniform in [-bound, bound], with a fixed ``delay`` [s] per
    evaluation if given (used by the benchmarks too: benchmarks/study_scaling.py)."""
    lines = ["[study]", *([f'name = "{name}"'] if name else []),
             'function = "tests.studyfunctions:ishigami"', f'design = "{design}"',
             f"samples = {samples}", f"seed = {seed}", 'quantities = ["y"]', "[parameters]",
             *(f"x{i} = {{ range = [-{bound!r}, {bound!r}] }}" for i in (1, 2, 3)),
             *([f"delay = {{ values = [{delay!r}] }}"] if delay is not None else [])]
    return "\n".join(lines) + "\n"


def in_ci() -> bool:
    """True in continuous integration: ``PDEFLOW_CI=1`` (set by .ci/run) or the ``CI``
    variable that CI services set (``true`` or ``1``)."""
    return (os.environ.get("PDEFLOW_CI") == "1"
            or os.environ.get("CI", "").lower() in ("1", "true"))


def skip_or_fail_in_ci(reason: str) -> None:
    """Skip the calling test because ``reason`` (something it needs is missing here);
    in CI (see in_ci) fail it instead: CI installs everything, so a missing piece there
    is a broken installation, not a test to skip."""
    if in_ci():
        pytest.fail(f"{reason} (in CI this is a failure, not a skip: .ci/run installs "
                    "the test extra, pip install '.[test]')", pytrace=False)
    pytest.skip(reason)


def assert_no_temporaries(folder: Path) -> None:
    """No file or directory below ``folder`` still has the ``.part`` of a file being
    written (outputs are written under a temporary name and renamed when complete)."""
    left = [p.name for p in folder.rglob("*") if ".part" in p.name]
    assert not left, f"temporary files left behind: {left}"


GENERATE = Path(__file__).resolve().parents[1] / "docs" / "generate"
"""the docs' generators (a directory of scripts, not a package)"""


@contextlib.contextmanager
def generator_modules(*names: str) -> Iterator[tuple]:
    """The modules ``names`` of docs/generate, with that directory on the path while the
    block runs (they import each other, some when called)."""
    sys.path.insert(0, str(GENERATE))
    try:
        yield tuple(importlib.import_module(n) for n in names)
    finally:
        sys.path.remove(str(GENERATE))


def cli_warnings(case: Path, overrides: list[str], tmp_path: Path, capsys) -> list[str]:
    """The ``pdeflow: warning:`` lines ``pdeflow run case --set ...`` prints (quietly,
    its outputs in ``tmp_path``)."""
    from pdeflow.cli import main

    capsys.readouterr()
    argv = ["run", str(case), "--outdir", str(tmp_path), "--quiet"]
    for o in overrides:
        argv += ["--set", o]
    assert main(argv) == 0
    return [r for r in capsys.readouterr().err.splitlines()
            if r.startswith("pdeflow: warning:")]


QUICK_2D = (("hll", 1, "minmod", False), ("rusanov", 2, "minmod", True),
            ("ifcp", 2, "mc", False))
"""The 2D schemes (flux, order, limiter, Strang?) of the default suite's runs over every
scheme: each flux, reconstruction/limiter and splitting once. Each scheme compiles its
own 2D stepping loop (10-100 s on a cold kernel cache), so the other 15 run with
``-m slow``."""


def schemes_2d(schemes: list[tuple]) -> list:
    """``(scheme, strang)`` parameters for every scheme of ``schemes`` ((flux, order,
    limiter)) with Lie and Strang: those of :data:`QUICK_2D` in the default suite, the
    others marked slow; ids such as ``hll/2/mc-strang``."""
    return [pytest.param(s, strang, id=f"{'/'.join(map(str, s))}-{('lie', 'strang')[strang]}",
                         marks=() if (*s, strang) in QUICK_2D else pytest.mark.slow)
            for s in schemes for strang in (False, True)]
