"""The final-state figure of a 2D run (issue 36, :mod:`pdeflow.figures_2d`): ``pdeflow
run CASE2D --plot OUT.png`` and the run's folder write it, complete or not at all; its
maps and cross-sections are those of the runs, and its deposit outline is where the
final depth exceeds the case's front threshold. The 1D ``--plot`` stays as it was."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pdeflow import metrics_2d
from pdeflow.cases import load_case
from pdeflow.cli import main
from pdeflow.simulate import run_model

ROOT = Path(__file__).resolve().parents[1]
CYLINDER = ROOT / "cases" / "cylinder_2d.toml"
SLOPE = ROOT / "cases" / "column_on_slope_2d.toml"
RITTER = ROOT / "cases" / "ritter_dam_break.toml"
COARSE = ["grid.dx=0.1"]  # 40 x 40 cells: the cylinder in a fraction of a second
PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def cylinder():
    """Both models of the cylinder on 40 x 40 cells."""
    case = load_case(CYLINDER, COARSE)
    return {m: run_model(case, m) for m in case.models}


def _figure(results):
    from pdeflow.case_figures import _stops
    from pdeflow.figures_2d import final_figure_job

    make, args, _ = final_figure_job(results, "unused.png", _stops(list(results.values())))
    return make(*args)


def _panels(fig) -> list:
    """The figure's axes without the colour bars."""
    return [ax for ax in fig.axes if ax.get_label() != "<colorbar>"]


def test_plot_writes_the_2d_figure_of_both_models(tmp_path, capsys):
    """--plot and --outdir together: the figure at both (and nothing else left)."""
    out, folder = tmp_path / "cyl.png", tmp_path / "od"
    assert main(["run", str(CYLINDER), *[f"--set={s}" for s in COARSE],
                 "--plot", str(out), "--outdir", str(folder)]) == 0
    assert out.read_bytes().startswith(PNG)
    assert f"wrote {out}" in capsys.readouterr().out
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cyl.png", "od"]
    assert sorted(p.name for p in folder.iterdir()) == ["final_deposits.png",
                                                        "summary.json"]


def test_the_default_folder_of_a_2d_run_holds_its_summary_and_figure(tmp_path,
                                                                    monkeypatch):
    """Named as the 1D folder's final state: final_deposits.png beside summary.json."""
    monkeypatch.chdir(tmp_path)
    assert main(["run", str(SLOPE), "-q", "--set", "case.models=['single_layer']"]) == 0
    folder = tmp_path / "results" / "column_on_slope_2d--case.models=single_layer"
    assert sorted(p.name for p in folder.iterdir()) == ["final_deposits.png",
                                                        "summary.json"]
    assert (folder / "final_deposits.png").read_bytes().startswith(PNG)


def test_the_figure_has_a_row_of_maps_per_model_and_the_cross_sections(cylinder):
    """Two layers: depth and speed of each layer (4 maps); one layer: 2 maps; then the
    two cross-sections, each with both models and the released state."""
    fig = _figure(cylinder)
    panels = _panels(fig)
    assert len(panels) == 4 + 2 + 2
    titles = [ax.get_title() for ax in panels]
    t2 = cylinder["two_layer"].t_final
    assert titles[0] == f"two layers, t = {t2:.3g} s\nupper depth $h_1$ [m]"
    assert titles[3] == f"two layers, t = {t2:.3g} s\nlower speed $|u_2|$ [m/s]"
    assert titles[4].startswith("single layer, t = ") and "depth $h$ [m]" in titles[4]
    assert titles[5].endswith("speed $|u|$ [m/s]")
    assert titles[6].startswith("along x at y = ") and "release centre" in titles[6]
    assert titles[7].startswith("along y at x = ") and "deepest cell" in titles[7]
    for ax in panels[:6]:
        assert (ax.get_xlabel(), ax.get_ylabel()) == ("x [m]", "y [m]")
        assert ax.get_aspect() == 1.0
    for ax in panels[6:]:
        labels = [t.get_text() for t in ax.get_legend().get_texts()]
        assert labels == ["two layers", "single layer", "initial state"]
    title = fig._suptitle.get_text()
    assert title.startswith("cylinder 2d: final state") and "_" not in title


def test_a_one_model_case_has_one_row_of_maps():
    case = load_case(SLOPE, ["case.models=['single_layer']"])
    fig = _figure({"single_layer": run_model(case, "single_layer")})
    panels = _panels(fig)
    assert len(panels) == 2 + 2
    assert panels[0].get_title().startswith("single layer, t = ")


def test_the_cross_sections_are_the_final_depths_through_the_centre(cylinder):
    fig = _figure(cylinder)
    ax_x, ax_y = _panels(fig)[6:]
    res = cylinder["single_layer"]
    x, y = res.state.grid.axes_coords
    total = metrics_2d.total_depth(res.state.data)
    j = int(np.argmin(np.abs(y - 0.0)))  # the release centre y0 = 0
    line = ax_x.get_lines()[1]
    np.testing.assert_array_equal(line.get_xdata(), x)
    np.testing.assert_array_equal(line.get_ydata(), total[:, j])
    deepest = np.max([metrics_2d.total_depth(r.state.data) for r in cylinder.values()],
                     axis=0)
    i = np.unravel_index(np.argmax(deepest), deepest.shape)[0]
    np.testing.assert_array_equal(ax_y.get_lines()[1].get_ydata(), total[i, :])


@pytest.mark.parametrize("model", ["two_layer", "single_layer"])
def test_the_deposit_outline_is_where_the_depth_exceeds_the_threshold(cylinder, model):
    """The outline's path against the array: its vertices lie where the total depth,
    interpolated between cell centres, is the front threshold (1e-3 m), and the cell
    centres inside it are exactly the cells deeper than that (the summary's
    deposit_area)."""
    from matplotlib.path import Path as MPath
    from scipy.interpolate import RegularGridInterpolator

    res = cylinder[model]
    row = 0 if model == "two_layer" else 4
    ax = _panels(_figure(cylinder))[row]
    outline = next(c for c in ax.collections if c.get_label() == "deposit")
    thr = res.case.front_threshold
    x, y = res.state.grid.axes_coords
    total = metrics_2d.total_depth(res.state.data)
    polygons = [p for path in outline.get_paths() for p in path.to_polygons()]
    assert polygons
    vertices = np.concatenate(polygons)
    depth_at = RegularGridInterpolator((x, y), total)(vertices)
    np.testing.assert_allclose(depth_at, thr, rtol=1e-6)
    X, Y = np.meshgrid(x, y, indexing="ij")
    centres = np.column_stack([X.ravel(), Y.ravel()])
    inside = np.zeros(len(centres), dtype=int)
    for p in polygons:  # even-odd: a hole in the deposit is outside
        inside += MPath(p).contains_points(centres)
    wet = (total > thr).ravel()
    np.testing.assert_array_equal(inside % 2 == 1, wet)
    area = wet.sum() * res.case.dx * res.case.dy
    assert area == pytest.approx(res.summary["deposit_area"])


def test_a_bad_plot_suffix_of_a_2d_case_is_one_line_before_any_run(tmp_path, capsys,
                                                                   monkeypatch):
    import pdeflow.simulate as sim

    def refuse(*args, **kwargs):
        raise AssertionError("a run started")

    monkeypatch.setattr(sim.Run, "execute", refuse)
    assert main(["run", str(CYLINDER), "--plot", str(tmp_path / "p.xyz")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("pdeflow: error: --plot") and err.count("\n") == 1, err
    assert "'.xyz'" in err and list(tmp_path.iterdir()) == []


def _no_figure(*args):
    """A figure that fails (module-level: the jobs go to the figure worker pickled)."""
    raise ValueError("no figure here")


@pytest.mark.parametrize("where", ["run", "figure"])
def test_an_interrupted_or_failed_2d_run_writes_no_figure(where, tmp_path, monkeypatch,
                                                          capsys):
    """Ctrl-C during the second model's run, or a figure that fails to draw: neither
    --plot nor the summary beside it is written, nor any temporary."""
    import pdeflow.figures_2d as f2d
    import pdeflow.simulate as sim

    if where == "run":
        execute = sim.Run.execute

        def interrupted(self, *args, **kwargs):
            if self.model == "single_layer":
                raise KeyboardInterrupt
            return execute(self, *args, **kwargs)

        monkeypatch.setattr(sim.Run, "execute", interrupted)
    else:
        monkeypatch.setattr(f2d, "final_figure_2d", _no_figure)
    out = tmp_path / "out"
    out.mkdir()
    args = ["run", str(CYLINDER), *[f"--set={s}" for s in COARSE], "--plot",
            str(out / "p.png"), "--summary", str(out / "s.json")]
    if where == "run":
        assert main(args) == 130
        assert "nothing written" in capsys.readouterr().err
    else:
        with pytest.raises(Exception, match="no figure here"):
            main(args)
    assert list(out.iterdir()) == []


def test_plot_of_a_1d_case_is_the_final_deposit_figure_as_before(tmp_path):
    from pdeflow.case_figures import deposit_figure, run_figure_jobs

    case = load_case(RITTER, ["grid.cells=40"])
    results = {m: run_model(case, m) for m in case.models}
    jobs = run_figure_jobs(results, None, tmp_path / "p.png")
    assert [(make, path) for make, _, path in jobs] == [(deposit_figure,
                                                         tmp_path / "p.png")]
    assert main(["run", str(RITTER), "-q", "--set", "grid.cells=40", "--plot",
                 str(tmp_path / "q.png")]) == 0
    assert (tmp_path / "q.png").read_bytes().startswith(PNG)


@pytest.mark.filterwarnings("ignore:.*still moving")  # stopped early, on purpose
def test_the_maps_are_the_final_depths_and_speeds_of_a_moving_run():
    """Stopped at t_end = 0.1 s, still moving: each map's colours are its layer's final
    depth (blank where dry) and speed |(hu, hv)|/h [m/s]; nothing says 'at rest'."""
    case = load_case(CYLINDER, [*COARSE, "case.t_end=0.1", "case.models=['two_layer']"])
    res = run_model(case, "two_layer")
    assert not res.summary["at_rest"]
    panels = _panels(_figure({"two_layer": res}))
    d = res.state.data
    for k in range(2):
        h, hu, hv = d[3 * k], d[3 * k + 1], d[3 * k + 2]
        wet = h > 1e-9
        depth = panels[2 * k].collections[0].get_array().reshape(h.T.shape)
        np.testing.assert_array_equal(depth.T[wet], h[wet])
        assert np.all(np.ma.getmaskarray(depth.T) | ~np.isfinite(depth.T) == ~wet)
        speed = panels[2 * k + 1].collections[0].get_array().reshape(h.T.shape).T
        moving = np.isfinite(speed)
        assert moving.any() and np.nanmax(speed) > 0.5
        np.testing.assert_allclose(speed[moving], np.hypot(hu, hv)[moving] / h[moving])
        assert not [t for t in panels[2 * k + 1].texts if t.get_text() == "at rest"]


def _summary(path: Path) -> dict:
    """A summary file's models without their wall times."""
    import json

    models = json.loads(path.read_text())["models"]
    for m in models.values():
        m.pop("wall_time_s")
    return models


def test_the_snapshots_of_a_2d_case_are_figures_beside_the_final_state(tmp_path):
    """output.snapshot_times on a 2D case: snapshot_t<t>.png in the run's folder, and
    the summary is the one of the run without snapshots."""
    folder = tmp_path / "od"
    snaps = "output.snapshot_times=[0.1, 0.3]"
    assert main(["run", str(CYLINDER), "-q", *[f"--set={s}" for s in (*COARSE, snaps)],
                 "--outdir", str(folder), "--summary", str(tmp_path / "with.json")]) == 0
    assert sorted(p.name for p in folder.iterdir()) == [
        "final_deposits.png", "snapshot_t0.1.png", "snapshot_t0.3.png", "summary.json"]
    assert (folder / "snapshot_t0.3.png").read_bytes().startswith(PNG)
    assert main(["run", str(CYLINDER), "-q", *[f"--set={s}" for s in COARSE],
                 "--summary", str(tmp_path / "without.json")]) == 0
    assert _summary(tmp_path / "with.json") == _summary(tmp_path / "without.json")


def test_a_snapshot_figure_maps_the_state_at_its_time_on_one_extent():
    """Each snapshot's depth maps are its stored state's depths; every snapshot of the
    case is drawn on the same extent (that of the material at any time)."""
    from pdeflow.figures_2d import snapshot_figure_jobs

    case = load_case(CYLINDER, [*COARSE, "output.snapshot_times=[0.05, 0.3]",
                                "case.models=['single_layer']"])
    res = run_model(case, "single_layer")
    jobs = snapshot_figure_jobs({"single_layer": res}, Path("unused"))
    assert [path.name for _, _, path in jobs] == ["snapshot_t0.05.png", "snapshot_t0.3.png"]
    limits = []
    for (make, args, _), t in zip(jobs, (0.05, 0.3), strict=True):
        fig = make(*args)
        panels = _panels(fig)
        assert panels[0].get_title().startswith(f"single layer, t = {t:g} s")
        assert fig._suptitle.get_text().startswith(f"cylinder 2d: t = {t:g} s")
        h = res.snapshots[t][0][0]
        wet = h > 1e-9
        depth = panels[0].collections[0].get_array().reshape(h.T.shape).T
        np.testing.assert_array_equal(depth[wet], h[wet])
        limits.append((panels[0].get_xlim(), panels[0].get_ylim()))
    assert limits[0] == limits[1]
    early, late = (metrics_2d.total_depth(res.snapshots[t][0]) for t in (0.05, 0.3))
    assert np.count_nonzero(late > 1e-3) > np.count_nonzero(early > 1e-3)  # it spread
