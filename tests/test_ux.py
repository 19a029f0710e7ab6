"""For the people who use it: case files, CLI, live plots, stored runs, docs.

Runs headless (the Agg backend is forced below) on small grids.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402

from pdeflow.analysis import mangeney, ritter  # noqa: E402
from pdeflow.cases import SCHEMA, load_case  # noqa: E402
from pdeflow.cli import build_parser, main  # noqa: E402
from pdeflow.simulate import run_model  # noqa: E402
from pdeflow.trackers import FextraStorageTracker  # noqa: E402
from pdeflow.trackers.live import LayersPlotTracker, MovieError, ffmpeg_path  # noqa: E402

ROOT = Path(__file__).parents[1]
CASES = sorted((ROOT / "cases").glob("*.toml"))
DOCS = ROOT / "docs"
RITTER = ROOT / "cases" / "ritter_dam_break.toml"
COARSE = ["grid.cells=100", "output.snapshot_times=[]"]

h5py = pytest.importorskip("h5py")


def _no_temporaries(folder: Path) -> None:
    left = [p.name for p in folder.rglob("*") if ".part" in p.name]
    assert not left, f"temporary files left behind: {left}"


# --- case files ---------------------------------------------------------------------------
def _is_sweep(path: Path) -> bool:
    """Sweep files (a [sweep] section, run by `pdeflow sweep`) are checked elsewhere."""
    from pdeflow.cases import tomllib

    return bool(set(tomllib.loads(path.read_text())) - set(SCHEMA))


@pytest.mark.parametrize("path", CASES, ids=[p.stem for p in CASES])
def test_every_case_file_loads_and_is_documented(path):
    assert path.name in (DOCS / "cases.md").read_text(), "docs/cases.md must list it"
    if _is_sweep(path):
        pytest.skip("not a plain case file (a sweep or a study file)")
    case = load_case(path)
    for model in case.models:
        eq, state = case.make_state(model)
        assert state.data[::2].sum() > 0  # there is material


def test_cases_md_documents_every_key():
    from dataclasses import fields

    from pdeflow.models import SingleLayerParameters, TwoLayerParameters

    text = (DOCS / "cases.md").read_text()
    keys = {section: list(keys) for section, keys in SCHEMA.items()}
    keys["two_layer"] = [f.name for f in fields(TwoLayerParameters)]
    keys["single_layer"] = [f.name for f in fields(SingleLayerParameters)]
    for section, names in keys.items():
        assert f"[{section}]" in text, section
        for key in names:
            assert f"`{key}`" in text, f"{section}.{key} not documented in docs/cases.md"


def test_paper_5_1_defaults_unchanged():
    case = load_case(ROOT / "cases" / "paper_5_1_dam_break.toml")
    assert (case.L0, case.initial["H0"], case.dx, case.length, case.cfl) == (
        1.0, 2.0, 0.05, 7.0, 0.3)


def test_ritter_case_matches_the_exact_solution():
    case = load_case(RITTER, ["output.snapshot_times=[]"])
    res = run_model(case, "single_layer")
    h, u = ritter(res.x, case.t_end, 0.1)
    err = np.abs(res.state.data[0] - h).sum() * case.dx / (0.1 * 1.0)
    assert err < 0.02, err  # relative L1 error of the depth, 400 cells


def test_mangeney_case_matches_the_exact_solution():
    case = load_case(ROOT / "cases" / "mangeney_dam_break_slope.toml",
                     ["output.snapshot_times=[]"])
    res = run_model(case, "single_layer")
    h, _ = mangeney(res.x, case.t_end, 0.1, theta_deg=30, delta_deg=20)
    err = np.abs(res.state.data[0] - h).sum() * case.dx / (0.1 * 1.0)
    assert err < 0.02, err


def test_heap_at_rest_case_stays_at_rest():
    case = load_case(ROOT / "cases" / "heap_at_rest.toml")
    for model in case.models:
        eq, state = case.make_state(model)
        res = run_model(case, model)
        assert res.summary["at_rest"] and res.t_final < 0.01
        assert np.all(res.state.data[1::2] == 0)  # no momentum anywhere
        # no mass moved between cells (two layers: the upper layer, at rest on the
        # lower one, is deposited into it, so the mass r h1 + h2 per cell is compared)
        w = [eq.parameters.density_ratio, 1.0] if model == "two_layer" else [1.0]
        mass = [np.dot(w, d[::2]) for d in (res.state.data, state.data)]
        np.testing.assert_allclose(mass[0], mass[1], atol=1e-12)


def test_paper_5_2_example_two_layer_runout_shorter():
    case = load_case(ROOT / "cases" / "paper_5_2_single_collapse.toml",
                     ["output.snapshot_times=[]"])
    r = {m: run_model(case, m).summary for m in case.models}
    assert r["two_layer"]["at_rest"] and r["single_layer"]["at_rest"]
    assert r["two_layer"]["runout"] < 0.8 * r["single_layer"]["runout"]


# --- live plots ---------------------------------------------------------------------------
def test_live_plot_headless_frames_gif_and_final_frame(tmp_path):
    from PIL import Image

    case = load_case(RITTER, COARSE)
    live = LayersPlotTracker(0.1, title="ritter", movie=tmp_path / "m.gif",
                           frames=tmp_path / "frames", display="none", dpi=50)
    res = run_model(case, "single_layer", tracker=live)
    assert live.display == "none"
    np.testing.assert_allclose(live.times, [0, 0.1, 0.2, 0.3, 0.4, 0.5], atol=1e-9)
    assert len(list((tmp_path / "frames").glob("frame_*.png"))) == 6
    with Image.open(tmp_path / "m.gif") as im:
        assert im.n_frames == 6
    # what is drawn is the final state, with its time in the title
    fig = live.figure
    assert "t = 0.500 s" in fig.fig._suptitle.get_text()
    surface = fig._lines[0]["surface"].get_ydata()
    h = res.state.data[0]
    np.testing.assert_allclose(np.nan_to_num(surface), np.where(h > 1e-9, h, 0))
    _no_temporaries(tmp_path)


def test_live_plot_last_frame_is_the_rest_state(tmp_path):
    case = load_case(ROOT / "cases" / "heap_slumping.toml",
                     ["output.snapshot_times=[]", "grid.dx=0.02"])
    live = LayersPlotTracker(0.2, display="none")
    res = run_model(case, "single_layer", tracker=live)
    assert res.summary["at_rest"]
    assert live.times[-1] == pytest.approx(res.info["solver"]["rest_time"])
    assert live.times[-2] < live.times[-1] < live.times[-2] + 0.2


@pytest.mark.skipif(ffmpeg_path() is None, reason="no ffmpeg (pip install imageio-ffmpeg)")
def test_live_plot_mp4(tmp_path):
    case = load_case(RITTER, COARSE)
    run_model(case, "single_layer",
              tracker=LayersPlotTracker(0.1, movie=tmp_path / "m.mp4", display="none",
                                      dpi=50))
    data = (tmp_path / "m.mp4").read_bytes()
    assert len(data) > 1000 and data[4:8] == b"ftyp"  # an MP4 container
    _no_temporaries(tmp_path)


def test_live_plot_updates_in_place_in_jupyter(monkeypatch):
    import IPython.display

    calls = []

    class Handle:
        def update(self, obj):
            calls.append(("update", obj))

    def fake_display(obj, display_id=False):
        calls.append(("display", obj))
        assert display_id is True
        return Handle()

    monkeypatch.setattr(IPython.display, "display", fake_display)
    case = load_case(RITTER, COARSE)
    live = LayersPlotTracker(0.25, display="jupyter")
    run_model(case, "single_layer", tracker=live)
    assert [c[0] for c in calls] == ["display", "update", "update"]
    for _, image in calls:  # PNG images of the figure, one per frame
        assert isinstance(image, IPython.display.Image) and image.data[:4] == b"\x89PNG"


def test_live_plot_window_mode_uses_pyplot(recwarn):
    import matplotlib.pyplot as plt

    case = load_case(RITTER, COARSE)
    live = LayersPlotTracker(0.25, display="window")
    run_model(case, "single_layer", tracker=live)
    assert plt.fignum_exists(live.figure.fig.number)  # left open for plt.show()
    live.figure.close()
    assert not plt.fignum_exists(live.figure.fig.number)


def test_live_plot_display_auto_is_headless_under_agg():
    assert LayersPlotTracker(0.1).display == "none"
    with pytest.raises(ValueError, match="display"):
        LayersPlotTracker(0.1, display="screen")
    with pytest.raises(MovieError, match="unknown movie format"):
        LayersPlotTracker(0.1, movie="x.avi2")


def test_live_plot_two_layer_draws_fextra(tmp_path):
    case = load_case(ROOT / "cases" / "paper_5_1_dam_break.toml",
                     ["grid.dx=0.1", "case.t_end=0.1", "output.snapshot_times=[]"])
    snaps = FextraStorageTracker([0.05, 0.1])
    live = LayersPlotTracker([0.05, 0.1], display="none")
    run_model(case, "two_layer", tracker=[snaps, live])
    drawn = live.figure._lines[0]["fextra"].get_ydata()
    np.testing.assert_array_equal(drawn, snaps.snapshots[0.1][1])
    assert "two_layer" == live.figure.series[0].model


# --- storage ------------------------------------------------------------------------------
def test_store_reopen_metadata_and_fextra(tmp_path):
    from pdeflow.storage import RunStorageTracker, open_run, open_storage, run_metadata

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
    from pdeflow.storage import open_run

    run = open_run(a)
    np.testing.assert_allclose(table[-100:, 2], run.data[-1, 0], rtol=1e-9)
    assert main(["export", str(a), str(tmp_path / "a.npz"), "-q"]) == 0
    with np.load(tmp_path / "a.npz") as f:
        assert f["h"].shape == (6, 100)
    _no_temporaries(tmp_path)


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


def test_progress_bar_only_on_a_terminal_or_asked(monkeypatch):
    from pdeflow.cli import _run_trackers
    from pdeflow.trackers import ProgressBar as ProgressTracker

    case = load_case(RITTER)
    parser = build_parser()

    def kinds(argv):
        args = parser.parse_args(["run", str(RITTER), *argv])
        return [type(t) for t in _run_trackers(args, case, "single_layer", True)]

    monkeypatch.setattr("sys.stdout.isatty", lambda: False)
    assert ProgressTracker not in kinds([])
    assert ProgressTracker in kinds(["--progress"])
    monkeypatch.setattr("sys.stdout.isatty", lambda: True)
    assert ProgressTracker in kinds([])
    assert ProgressTracker not in kinds(["--no-progress"])
    assert ProgressTracker not in kinds(["-q"])


def test_every_cli_option_has_help():
    parser = build_parser()
    subparsers = next(a for a in parser._actions if a.choices and "run" in a.choices)
    for name in ("run", "plot", "export"):
        sub = subparsers.choices[name]
        assert sub.description, name
        for action in sub._actions:
            assert action.help and len(action.help) > 10, (name, action.dest)


# --- docs ---------------------------------------------------------------------------------
def test_readme_links_every_doc_and_keeps_the_quick_start():
    readme = (ROOT / "README.md").read_text()
    assert 'pip install ".[test]" && pdeflow run cases/paper_5_1_dam_break.toml' in readme
    assert "python -m pytest -q" in readme
    section = readme.split("## Documentation", 1)[1].split("\n## ", 1)[0]
    for doc in sorted(DOCS.glob("*.md")) + sorted(DOCS.glob("*.ipynb")):
        assert f"(docs/{doc.name})" in section, f"README does not link docs/{doc.name}"


def test_every_doc_figure_exists_and_names_its_command():
    """Each image in docs/*.md exists, and either the text right around it gives the
    command that makes it (naming the file), or the whole document says at its top that
    it is generated by a command."""
    found = 0
    for doc in DOCS.glob("*.md"):
        lines = doc.read_text().splitlines()
        generated = "Generated by `" in "\n".join(lines[:6])
        for i, line in enumerate(lines):
            for ref in re.findall(r"!\[[^\]]*\]\(([^)]+)\)", line):
                found += 1
                assert (doc.parent / ref).is_file(), f"{doc.name}: missing {ref}"
                if generated:
                    continue
                near = "\n".join(lines[max(0, i - 12):i + 12])
                assert Path(ref).name in near.replace(line, ""), (doc.name, ref)
                assert re.search(r"pdeflow (run|plot|export)|python ", near), (doc.name, ref)
    assert found >= 3
