"""Stored runs of 2D cases (issue 36): ``pdeflow run CASE2D --store`` writes the run on
the 2D grid with its metadata, without changing the run's numbers; ``pdeflow export``
writes NetCDF (time, x, y), NPZ and CSV that read back to the stored values; ``pdeflow
plot`` draws a 2D run's stored state and its movie; bad input is one line before any
work. Needs h5py (the test extra); NetCDF needs xarray."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from pdeflow.cli import main

from .helpers import assert_no_temporaries

ROOT = Path(__file__).parents[1]
CYLINDER = ROOT / "cases" / "cylinder_2d.toml"
# a coarse, short cylinder collapse on a box that is not square (20 x 16 cells of
# 0.2 m), so that x and y cannot be swapped unnoticed; both models, F_extra acts
SMALL = ["--set", "grid.dx=0.2", "--set", "grid.width=3.2", "--set", "case.t_end=0.6"]
EVERY = 0.2

h5py = pytest.importorskip("h5py")


@pytest.fixture(scope="module")
def stored(tmp_path_factory):
    """One run of :data:`SMALL` without and one with --store: (folder, summaries
    without, summaries with)."""
    d = tmp_path_factory.mktemp("store2d")
    assert main(["run", str(CYLINDER), *SMALL, "--summary", str(d / "plain.json"),
                 "--final", str(d / "final.npz"), "-q"]) == 0
    assert main(["run", str(CYLINDER), *SMALL, "--summary", str(d / "stored.json"),
                 "--store", str(d / "a.h5"), "--store-every", str(EVERY), "-q"]) == 0
    plain = json.loads((d / "plain.json").read_text())["models"]
    with_store = json.loads((d / "stored.json").read_text())["models"]
    return d, plain, with_store


def test_storing_does_not_change_the_runs_numbers(stored):
    d, plain, with_store = stored
    assert set(plain) == set(with_store) == {"two_layer", "single_layer"}
    for model in plain:
        a = {k: v for k, v in plain[model].items() if k != "wall_time_s"}
        b = {k: v for k, v in with_store[model].items() if k != "wall_time_s"}
        assert a == b, model  # every number, bit for bit
    assert_no_temporaries(d)


def test_the_store_holds_the_2d_frames_and_metadata(stored):
    from pdeflow.storage import open_storage, stored_axes
    from pdeflow.storage_2d import StoredRun2D
    from pdeflow.stored_runs import open_run

    d, plain, _ = stored
    for model, path, final in (("two_layer", d / "a.h5", d / "final.npz"),
                               ("single_layer", d / "a.single_layer.h5",
                                d / "final.single_layer.npz")):
        run = open_run(path)
        assert isinstance(run, StoredRun2D) and stored_axes(path) == 2
        assert run.model == model and run.x.size == 20 and run.y.size == 16
        np.testing.assert_allclose(run.x, -2.0 + 0.2 * (np.arange(20) + 0.5))
        np.testing.assert_allclose(run.y, -2.0 + 0.2 * (np.arange(16) + 0.5))
        assert run.data.shape[1:] == (6 if model == "two_layer" else 3, 20, 16)
        assert run.fextra.shape == (len(run.times), 20, 16)
        # frames at t = 0, every EVERY s, and the end (the rest time or t_end)
        t_end = plain[model]["t_final"]
        expected = [t for t in np.arange(0, t_end, EVERY) if t < t_end - 1e-9] + [t_end]
        np.testing.assert_allclose(run.times, expected, atol=1e-9)
        assert run.index(0.25) == 1 and run.index(None) == len(run.times) - 1
        saved, last = np.load(final), run.profiles(-1)
        for name in run.columns():
            if name in saved:  # the final frame is the run's final state (--final)
                np.testing.assert_array_equal(last[name], saved[name], err_msg=name)
        m = run.metadata
        assert m["dimensions"] == 2 and m["dy"] == 0.2 and m["width"] == 3.2
        assert m["cells_y"] == 16 and m["y_start"] == -2.0 and m["store_every"] == EVERY
        assert m["summary"]["front_position"] == plain[model]["front_position"]
        assert m["units"]["h1v1" if model == "two_layer" else "hv"] == "m^2/s"
        assert "2D grid 20 x 16 cells" in run.describe()
    two = open_run(d / "a.h5")
    assert two.fextra.max() > 0  # the restoration acted, and its field is kept per cell
    storage = open_storage(d / "a.h5")  # a plain py-pde storage too
    assert storage[-1].labels == ["h1", "h1u1", "h1v1", "h2", "h2u2", "h2v2",
                                  "fextra_over_rho1"]
    storage.close()


def test_export_netcdf_has_time_x_y_and_cf_attributes(stored):
    xr = pytest.importorskip("xarray")
    from pdeflow.stored_runs import open_run

    d, _, _ = stored
    nc = d / "a.nc"
    assert main(["export", str(d / "a.h5"), str(nc), "-q"]) == 0
    run = open_run(d / "a.h5")
    with xr.open_dataset(nc) as ds:
        assert set(ds.data_vars) == {"h1", "u1", "v1", "h2", "u2", "v2",
                                     "fextra_over_rho1"}
        for name in ds.data_vars:
            assert ds[name].dims == ("time", "x", "y")
            assert ds[name].attrs["long_name"] and ds[name].attrs["units"]
        assert ds["h2"].attrs["units"] == "m" and ds["v1"].attrs["units"] == "m/s"
        assert "across the slope" in ds["v1"].attrs["long_name"]
        assert ds["fextra_over_rho1"].attrs["units"] == "m^2/s^2"
        assert ds["x"].attrs["units"] == "m" and ds["y"].attrs["units"] == "m"
        assert ds["time"].attrs["units"] == "s" and ds["time"].dtype == float
        np.testing.assert_array_equal(ds["x"].values, run.x)
        np.testing.assert_array_equal(ds["y"].values, run.y)
        np.testing.assert_array_equal(ds["time"].values, run.times)
        for i in range(len(run.times)):
            for name, values in run.profiles(i).items():
                np.testing.assert_array_equal(ds[name].values[i], values, err_msg=name)
        # t = 0.2 s, mid-collapse: the flow spreads along y as along x, and the
        # restoration acts in some cells
        assert np.abs(ds["v2"].values[1]).max() > 0.1
        assert ds["fextra_over_rho1"].values[1].max() > 0
        assert json.loads(ds.attrs["pdeflow_metadata"])["dimensions"] == 2
    assert_no_temporaries(d)


def test_export_npz_and_csv_of_a_2d_run(stored):
    from pdeflow.stored_runs import open_run

    d, _, _ = stored
    run = open_run(d / "a.single_layer.h5")
    nt = len(run.times)
    assert main(["export", str(d / "a.single_layer.h5"), str(d / "b.npz"), "-q"]) == 0
    with np.load(d / "b.npz") as f:
        assert f["h"].shape == f["v"].shape == (nt, 20, 16) and f["y"].shape == (16,)
        np.testing.assert_array_equal(f["u"][-1], run.profiles(-1)["u"])
    assert main(["export", str(d / "a.single_layer.h5"), str(d / "b.csv"), "-q"]) == 0
    assert (d / "b.csv").read_text().splitlines()[0] == "t,x,y,h,u,v"
    table = np.loadtxt(d / "b.csv", delimiter=",", skiprows=1)
    assert table.shape == (nt * 20 * 16, 6)
    last = table[-20 * 16:]  # the last frame, y fastest: the state's (nx, ny) order
    np.testing.assert_allclose(last[:, 3].reshape(20, 16), run.profiles(-1)["h"],
                               rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(last[:16, 2], run.y)


@pytest.mark.parametrize("extra", [[], ["--time", "0.2"]])
def test_plot_of_2d_runs_draws_their_maps_at_the_stored_time(stored, extra, capsys,
                                                             tmp_path, monkeypatch):
    """``pdeflow plot`` of stored 2D runs draws figures_2d's maps and sections of the
    stored state nearest to --time (the last by default), one axes per map and a
    section along x and y: both models' runs, 4 + 2 maps."""
    import matplotlib.image as mpimg

    d, _, _ = stored
    monkeypatch.chdir(tmp_path)
    assert main(["plot", str(d / "a.h5"), str(d / "a.single_layer.h5"), *extra,
                 "--out", "f.png", "-q"]) == 0
    assert capsys.readouterr().err == ""
    image = mpimg.imread(tmp_path / "f.png")
    assert image.shape[0] > 600 and image.shape[1] > 1000  # the maps' rows and sections
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f.png"]


def test_the_2d_plot_shows_the_state_asked_for(stored, monkeypatch):
    """The figure of a stored 2D run at --time holds that frame's depths (the maps'
    images), and its title says it is a stored state, not the final one."""
    from pdeflow import cli_stored, figures_2d
    from pdeflow.cli import build_parser
    from pdeflow.stored_runs import open_run

    d, _, _ = stored
    drawn = {}
    draw = figures_2d.final_figure_2d

    def spy(*args, **kwargs):
        drawn["runs"], drawn["times"], drawn["state"] = args[2], args[3], kwargs["state"]
        return draw(*args, **kwargs)

    monkeypatch.setattr(figures_2d, "final_figure_2d", spy)
    run = open_run(d / "a.single_layer.h5")
    i = run.index(0.2)
    args = build_parser().parse_args(["plot", str(d / "a.single_layer.h5"), "--time",
                                      "0.2", "--out", str(d / "g.png"), "-q"])
    cli_stored.cmd_plot(args)
    assert drawn["times"] == [float(run.times[i])] and drawn["state"] == "stored state"
    np.testing.assert_array_equal(drawn["runs"][0][1], run.data[i])


def test_a_movie_of_2d_runs_shows_every_stored_frame(stored, capsys, tmp_path,
                                                    monkeypatch):
    """``pdeflow plot A.h5 B.h5 --movie``: a frame per stored frame of the first run,
    both runs side by side at their frames nearest to its time (the plan view,
    :mod:`pdeflow.plan_view`); --movie alone writes no figure, with --out it does."""
    from PIL import Image

    from pdeflow.plan_view import PlanFigure
    from pdeflow.stored_runs import open_run

    d, _, _ = stored
    drawn = []
    update = PlanFigure.update

    def spy(self, t, states, fextras=None):
        drawn.append((t, states))
        return update(self, t, states, fextras)

    monkeypatch.setattr(PlanFigure, "update", spy)
    monkeypatch.chdir(tmp_path)
    runs = [open_run(d / "a.h5"), open_run(d / "a.single_layer.h5")]
    assert main(["plot", str(d / "a.h5"), str(d / "a.single_layer.h5"), "--movie",
                 "m.gif"]) == 0
    assert "wrote m.gif" in capsys.readouterr().out
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.gif"]
    with Image.open("m.gif") as im:
        assert im.n_frames == len(runs[0].times) == len(drawn)
    for (t, states), t0 in zip(drawn, runs[0].times, strict=True):
        assert t == t0
        for run, state in zip(runs, states, strict=True):
            np.testing.assert_array_equal(state, run.data[run.index(min(t, run.times[-1]))])
    assert main(["plot", str(d / "a.h5"), "--movie", "one.gif", "--out", "one.png",
                 "-q"]) == 0
    assert (tmp_path / "one.png").read_bytes().startswith(b"\x89PNG")
    assert_no_temporaries(tmp_path)


@pytest.mark.parametrize("option, words", [
    (["--store-every", "0", "--store", "s.h5"], ["--store-every", "> 0"]),
    (["--store-every", "-1", "--store", "s.h5"], ["--store-every", "> 0"]),
    (["--store", "s.txt"], ["--store", "s.txt"]),
    (["--store", "missing/s.h5"], ["--store", "missing"]),
])
def test_bad_store_options_of_a_2d_run_are_one_line(option, words, capsys, tmp_path,
                                                    monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["run", str(CYLINDER), *option]) == 2
    err = capsys.readouterr().err
    assert err.startswith("pdeflow: error:") and err.count("\n") == 1, err
    for w in words:
        assert w in err, (w, err)
    assert not list(tmp_path.iterdir())


def test_a_failed_2d_run_leaves_no_file(tmp_path, monkeypatch):
    """A 2D run that fails half-way keeps no stored file (nor a temporary), as in 1D."""
    import pdeflow.simulate as sim
    from pdeflow.trackers import FextraStorageTracker

    original = sim.run_model

    class Boom(RuntimeError):
        pass

    class Fail(FextraStorageTracker):
        def handle(self, field, t):
            if t > 0.2:
                raise Boom("simulated failure")

    def failing(case, model, *, tracker=None, **kw):
        return original(case, model, tracker=[*tracker, Fail(0.1)], **kw)

    monkeypatch.setattr(sim, "run_model", failing)
    with pytest.raises(Boom):
        main(["run", str(CYLINDER), *SMALL, "--store", str(tmp_path / "a.h5"), "-q"])
    assert list(tmp_path.iterdir()) == []


def test_a_1d_store_keeps_its_metadata_keys():
    """The y-axis keys are a 2D file's only: a 1D file's metadata is as before."""
    from pdeflow.cases import load_case
    from pdeflow.storage import run_metadata

    one = run_metadata(load_case(ROOT / "cases" / "ritter_dam_break.toml"), "single_layer")
    assert not {"dimensions", "dy", "width", "y_start", "cells_y"} & set(one)
    two = run_metadata(load_case(CYLINDER), "single_layer")
    assert two["dimensions"] == 2 and two["cells_y"] == 80


def test_plot_of_a_run_over_a_dem_reads_the_dem_next_to_its_case_file(tmp_path,
                                                                       monkeypatch):
    """A case's DEM is relative to the case file: a run stored from another folder is
    drawn from a third one (the store records the case file's folder)."""
    from pdeflow.terrain import Raster, write_raster

    cases, run_dir, elsewhere = (tmp_path / d for d in ("cases", "run", "elsewhere"))
    for d in (cases, run_dir, elsewhere):
        d.mkdir()
    xc = 10.0 * np.arange(32) - 5.0
    yc = 10.0 * np.arange(22)[::-1] - 105.0
    X, _ = np.meshgrid(xc, yc)  # noqa: N806
    write_raster(Raster(300.0 - 0.6 * X, -10.0, -110.0, 10.0, np.zeros(X.shape, bool)),
                 cases / "dem.asc")
    (cases / "case.toml").write_text(
        '[case]\nmodels = ["single_layer"]\nt_end = 2.0\n'
        "[grid]\nlength = 200.0\nwidth = 100.0\ndx = 20.0\ny_start = -50.0\n"
        '[terrain]\nbed = "dem.asc"\n'
        '[initial]\nshape = "box"\nx0 = 60.0\ny0 = 50.0\nsemi_x = 30.0\nsemi_y = 30.0\n'
        "H0 = 1.0\n")
    monkeypatch.chdir(run_dir)
    assert main(["run", str(cases / "case.toml"), "--store", "a.h5", "-q"]) == 0
    monkeypatch.chdir(elsewhere)
    assert main(["plot", str(run_dir / "a.h5"), "--out", "a.png", "-q"]) == 0
    assert (elsewhere / "a.png").stat().st_size > 0
