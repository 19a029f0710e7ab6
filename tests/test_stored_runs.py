"""Stored runs (HDF5, ``pdeflow run --store``): written with their metadata and F_extra,
reopened, plotted and compared (``pdeflow plot``), exported (CSV, npz, netCDF), made into
movies; a failed run leaves no file behind; their user errors are one line. Needs h5py
(the test extra)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from pdeflow.cases import load_case
from pdeflow.cli import main
from pdeflow.simulate import run_model
from pdeflow.trackers import FextraStorageTracker

from .helpers import assert_no_temporaries

ROOT = Path(__file__).parents[1]
RITTER = ROOT / "cases" / "ritter_dam_break.toml"

h5py = pytest.importorskip("h5py")


def test_store_reopen_metadata_and_fextra(tmp_path):
    from pdeflow.storage import RunStorageTracker, open_storage, run_metadata
    from pdeflow.stored_runs import open_run

    case = load_case(ROOT / "cases" / "paper_5_1_dam_break.toml",
                     ["grid.dx=0.1", "case.t_end=0.2", "output.snapshot_times=[]"])
    snaps = FextraStorageTracker(0.05)
    path = tmp_path / "run.h5"
    store = RunStorageTracker(path, 0.05, metadata=run_metadata(case, "two_layer"))
    res = run_model(case, "two_layer", tracker=[snaps, store])
    run = open_run(path)
    np.testing.assert_allclose(run.times, [0, 0.05, 0.1, 0.15, 0.2], atol=1e-9)
    np.testing.assert_array_equal(run.data[-1], res.state.data)
    for i, t in enumerate(run.times):
        np.testing.assert_array_equal(run.fextra[i], snaps.snapshots[round(t, 9)][1])
    assert run.fextra.max() > 0
    m = run.metadata
    assert m["model"] == "two_layer" and m["variant"].startswith("two_layer")
    assert m["case"]["initial"]["H0"] == 2.0 and m["parameters"]["phi_int_deg"] == 30
    assert m["pdeflow_version"] and m["py_pde_version"] and m["format"] == "pdeflow-run/1"
    assert m["t_final"] == pytest.approx(0.2) and m["stop_reason"] == "Reached final time"
    # the file is a plain py-pde storage too
    st = open_storage(path)
    assert st[-1].labels == ["h1", "h1u1", "h2", "h2u2", "fextra_over_rho1"]
    st.close()


def test_cli_store_plot_compare_and_export(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    a, b = tmp_path / "a.h5", tmp_path / "b.h5"
    base = ["run", str(RITTER), "--set", "grid.cells=100", "--store-every", "0.1", "-q"]
    assert main(base + ["--store", str(a)]) == 0
    assert main(base + ["--store", str(b), "--set", "initial.h_left=0.05"]) == 0
    assert not (tmp_path / "results").exists()  # --store is an output: no default dir
    meta = json.loads(h5py.File(a, "r").attrs["pdeflow"])
    assert meta["summary"]["model"] == "single_layer"
    assert meta["overrides"] == ["grid.cells=100"]
    assert meta["case_file"] == str(RITTER) and meta["store_every"] == 0.1
    fig = tmp_path / "cmp.png"
    assert main(["plot", str(a), str(b), "--time", "0.3", "--out", str(fig)]) == 0
    out = capsys.readouterr().out
    assert fig.stat().st_size > 10_000
    assert "a.h5: ritter_dam_break, single_layer, 6 frames" in out
    # export: CSV rows = frames x cells, values as stored
    csv = tmp_path / "a.csv"
    assert main(["export", str(a), str(csv), "-q"]) == 0
    table = np.loadtxt(csv, delimiter=",", skiprows=1)
    assert csv.read_text().splitlines()[0] == "t,x,h,u"
    assert table.shape == (6 * 100, 4)
    from pdeflow.stored_runs import open_run

    run = open_run(a)
    np.testing.assert_allclose(table[-100:, 2], run.data[-1, 0], rtol=1e-9)
    assert main(["export", str(a), str(tmp_path / "a.npz"), "-q"]) == 0
    with np.load(tmp_path / "a.npz") as f:
        assert f["h"].shape == (6, 100)
    assert_no_temporaries(tmp_path)


def test_export_netcdf(tmp_path):
    xr = pytest.importorskip("xarray")
    a = tmp_path / "a.h5"
    assert main(["run", str(RITTER), "--set", "grid.cells=50", "--store", str(a),
                 "--store-every", "0.25", "-q"]) == 0
    assert main(["export", str(a), str(tmp_path / "a.nc"), "-q"]) == 0
    ds = xr.open_dataset(tmp_path / "a.nc")
    assert ds["h"].shape == (3, 50) and ds["h"].attrs["units"] == "m"
    assert json.loads(ds.attrs["pdeflow_metadata"])["case_name"] == "ritter_dam_break"
    ds.close()


def test_cli_movie_of_stored_runs(tmp_path):
    a = tmp_path / "a.h5"
    assert main(["run", str(RITTER), "--set", "grid.cells=50", "--store", str(a),
                 "--store-every", "0.25", "-q"]) == 0
    assert main(["plot", str(a), "--movie", str(tmp_path / "a.gif"), "-q"]) == 0
    from PIL import Image

    with Image.open(tmp_path / "a.gif") as im:
        assert im.n_frames == 3


def test_failed_run_leaves_no_files(tmp_path, monkeypatch):
    """A run that fails half-way leaves neither the HDF5 file nor the movie behind."""
    import pdeflow.simulate as sim

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
        main(["run", str(RITTER), "--set", "grid.cells=50", "--store",
              str(tmp_path / "a.h5"), "--movie", str(tmp_path / "a.gif"),
              "--live-every", "0.1", "-q"])
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("argv, words", [
    (["plot", "missing.h5"], ["missing.h5", "does not exist"]),
    (["run", str(RITTER), "--movie", "x.avi2"], ["x.avi2", "movie format"]),
    (["run", str(RITTER), "--store-every", "0"], ["--store-every", "> 0"]),
    (["export", str(RITTER), "x.csv"], ["not an HDF5 file"]),
])
def test_cli_user_errors_are_one_line(argv, words, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("pdeflow: error:") and err.count("\n") == 1
    for w in words:
        assert w in err
