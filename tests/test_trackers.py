"""Trackers and the velocity helper: py-pde's storages with F_extra, one dry threshold,
and the layers (trackers import nothing of pdeflow above the numerics)."""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest
from pde import MemoryStorage

from pdeflow.cases import load_case
from pdeflow.io import atomic_path
from pdeflow.numerics.state import DRY_TOLERANCE, velocity, velocity_profile
from pdeflow.simulate import run_model
from pdeflow.trackers import FextraStorageTracker

ROOT = Path(__file__).parents[1]
CASE_51 = ROOT / "cases" / "paper_5_1_dam_break.toml"


def test_velocity_profile_is_the_kernels_rule():
    """Cell by cell the numpy helper gives what the kernels' pointwise velocity gives,
    with the same dry threshold (h <= dry: zero)."""
    dry = 1e-6
    h = np.array([0.0, 1e-12, 1e-7, dry, np.nextafter(dry, 1), 1e-3, 0.5, 2.0])
    m = np.array([0.0, 0.0, 3e-8, 2e-7, 2e-6, -1e-3, 0.25, 3.0])
    expected = [velocity.py_func(a, b, dry) for a, b in zip(h, m, strict=True)]
    np.testing.assert_array_equal(velocity_profile(h, m, dry), expected)
    gaps = velocity_profile(h, m, dry, fill=np.nan)
    assert np.isnan(gaps[:4]).all() and np.isfinite(gaps[4:]).all()
    assert velocity_profile(0.5, 0.25) == 0.5  # numbers too


def test_models_default_dry_tolerance_is_the_helpers():
    from pdeflow import SingleLayerParameters, TwoLayerParameters

    assert SingleLayerParameters().dry_tolerance == DRY_TOLERANCE
    assert TwoLayerParameters().dry_tolerance == DRY_TOLERANCE


def test_solver_states_carry_no_momentum_where_dry():
    """Why one threshold changes no output: the source stage zeroes the momentum of
    layers not thicker than dry_tolerance, so velocities with 1e-12 (the old threshold
    of stored runs and final states) and with dry_tolerance agree on every frame."""
    case = load_case(CASE_51, ["grid.dx=0.05", "case.t_end=0.6",
                               "output.snapshot_times=[]"])
    frames = FextraStorageTracker(0.05)
    with pytest.warns(Warning):  # still moving at t_end
        res = run_model(case, "two_layer", tracker=frames)
    dry = res.case.make_pde("two_layer").parameters.dry_tolerance
    thin_seen = 0
    for d, _ in frames.snapshots.values():
        for k in (0, 2):
            thin = (d[k] > 1e-12) & (d[k] <= dry)
            thin_seen += int(thin.sum())
            assert np.all(d[k + 1][d[k] <= dry] == 0.0)
            old = np.where(d[k] > 1e-12, d[k + 1] / np.where(d[k] > 1e-12, d[k], 1), 0.0)
            np.testing.assert_array_equal(velocity_profile(d[k], d[k + 1], dry), old)
    assert len(frames.snapshots) == 13
    assert thin_seen > 0  # the frames do hold layers thinner than dry_tolerance


def test_fextra_storage_tracker_fills_a_py_pde_memory_storage():
    case = load_case(CASE_51, ["grid.dx=0.1", "case.t_end=0.2", "output.snapshot_times=[]"])
    frames = FextraStorageTracker([0.1, 0.2])
    with pytest.warns(Warning):  # still moving at t_end
        res = run_model(case, "two_layer", tracker=frames)
    st = frames.storage
    assert isinstance(st, MemoryStorage)
    np.testing.assert_allclose(st.times, [0.1, 0.2], atol=1e-9)
    assert st[-1].labels == ["h1", "h1u1", "h2", "h2u2", "fextra_over_rho1"]
    np.testing.assert_array_equal(st[-1].data[:4], res.state.data)
    np.testing.assert_array_equal(st[-1].data[4], res.fextra_over_rho1)
    state, fextra = frames.snapshots[0.2]
    np.testing.assert_array_equal(state, res.state.data)
    assert fextra.max() > 0


def test_atomic_path_keeps_the_suffix_and_commits(tmp_path):
    """Writers that choose a format by the suffix see it on the temporary file too."""
    target = tmp_path / "a.nc"
    with atomic_path(target) as tmp:
        assert tmp.name.startswith(".a.nc.") and tmp.name.endswith(".part.nc")
        assert not target.exists()
        tmp.write_text("x")
    assert target.read_text() == "x" and [p.name for p in tmp_path.iterdir()] == ["a.nc"]


def _pdeflow_imports(path: Path) -> set[str]:
    """pdeflow modules that ``path`` imports (also inside functions), as dotted names."""
    pkg = ".".join(path.relative_to(ROOT).with_suffix("").parts[:-1])
    out = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            base = pkg.split(".")[:len(pkg.split(".")) - node.level + 1] if node.level \
                else []
            if node.module:
                out.add(".".join([*base, node.module]))
            else:  # from . import module, ...
                out.update(".".join([*base, a.name]) for a in node.names)
        elif isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
    return {n for n in out if n.split(".")[0] == "pdeflow"}


def test_trackers_sit_below_models_solvers_and_storage():
    """As in py-pde (a PDE's solve makes its trackers), pdeflow's trackers import only
    the numerics, io, plotting (the 2D plan view's figures and measures too) and the
    systems registry, never the models, solvers, storage or what is above."""
    allowed = ("pdeflow.numerics", "pdeflow.io", "pdeflow.plotting", "pdeflow.trackers",
               "pdeflow.systems", "pdeflow.plan_view")
    for path in sorted((ROOT / "pdeflow" / "trackers").glob("*.py")):
        bad = [n for n in _pdeflow_imports(path) if not n.startswith(allowed)]
        assert not bad, f"{path.name} imports {bad}"
    figures = ("pdeflow.numerics", "pdeflow.io", "pdeflow.systems")
    for name, more in (("io.py", ()), ("plotting.py", ()),
                       ("plan_view.py", ("pdeflow.plotting", "pdeflow.figures_2d",
                                         "pdeflow.metrics_2d")),
                       ("figures_2d.py", ("pdeflow.plotting", "pdeflow.metrics_2d",
                                          "pdeflow.terrain_figures")),
                       ("terrain_figures.py", ("pdeflow.plotting",)),
                       ("metrics_2d.py", ("pdeflow.metrics",)), ("metrics.py", ())):
        bad = [n for n in _pdeflow_imports(ROOT / "pdeflow" / name)
               if not n.startswith((*figures, *more))]
        assert not bad, f"{name} imports {bad}"
