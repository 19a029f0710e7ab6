"""Live plots, movies and PNG frames of 2D runs (issue 36): the plan view of
:mod:`pdeflow.plan_view` drawn by :class:`pdeflow.trackers.live.LayersPlotTracker`
(``pdeflow run CASE2D --live | --movie | --frames``); each frame is the state of the
run at its time, the outputs are complete or absent. Headless: tests/conftest.py forces
Agg. That the numbers of a run do not change is tests/test_observers.py's (its 2D
case), ``pdeflow plot RUN2D.h5 --movie`` tests/test_stored_runs_2d.py's."""

from __future__ import annotations

import os
import signal
from pathlib import Path

import numpy as np
import pytest

from pdeflow import metrics_2d
from pdeflow.cases import load_case
from pdeflow.cli import main
from pdeflow.plan_view import PlanFigure
from pdeflow.plotting import DRY
from pdeflow.simulate import run_model
from pdeflow.trackers import FextraStorageTracker
from pdeflow.trackers.live import LayersPlotTracker, ffmpeg_path

from .helpers import assert_no_temporaries

ROOT = Path(__file__).parents[1]
CYLINDER = ROOT / "cases" / "cylinder_2d.toml"
# a coarse, short cylinder collapse on a box that is not square (20 x 16 cells of
# 0.2 m), so that x and y cannot be swapped unnoticed; both models
SMALL = ["grid.dx=0.2", "grid.width=3.2", "case.t_end=0.6"]
SETS = [arg for s in SMALL for arg in ("--set", s)]
EVERY = 0.2


def _drawn(figure: PlanFigure, i: int = 0) -> np.ndarray:
    """The total depth [m] a map shows, (nx, ny), NaN where blank."""
    return np.ma.filled(figure._meshes[i].get_array(), np.nan).reshape(
        figure.series[i].y.size, figure.series[i].x.size).T


@pytest.mark.parametrize("model", ["two_layer", "single_layer"])
def test_the_live_plan_view_draws_each_frame_of_the_run(model, tmp_path):
    """Frames at 0, 0.2, 0.4 s and the end; each map is the total depth of the stored
    frame at its time (blank where dry), the deposit outline at the case's threshold,
    the time in the title; the GIF and the PNG frames hold every frame, at one size."""
    from PIL import Image

    case = load_case(CYLINDER, SMALL)
    frames = FextraStorageTracker(EVERY)
    live = LayersPlotTracker(EVERY, title="cyl", display="none", movie=tmp_path / "m.gif",
                             frames=tmp_path / "fr", dpi=40,
                             threshold=case.front_threshold)
    res = run_model(case, model, tracker=[frames, live])
    assert isinstance(live.figure, PlanFigure)
    t_end = res.t_final
    expected = [t for t in np.arange(0, t_end, EVERY) if t < t_end - 1e-9] + [t_end]
    np.testing.assert_allclose(live.times, expected, atol=1e-9)
    # the last frame drawn is the final state: the same numbers, passed through
    total = metrics_2d.total_depth(res.state.data)
    np.testing.assert_array_equal(_drawn(live.figure), np.where(total > DRY, total, np.nan))
    outline = live.figure._outlines[0]
    assert outline is not None and list(outline.levels) == [case.front_threshold]
    assert f"t = {t_end:.3f} s" in live.figure._title.get_text()
    assert live.figure._norm.vmin == 0 and live.figure._norm.vmax >= total.max()
    pngs = sorted((tmp_path / "fr").glob("frame_*.png"))
    assert len(pngs) == len(expected)
    sizes = set()
    for png in pngs:
        with Image.open(png) as im:
            im.load()
            sizes.add(im.size)
    assert len(sizes) == 1
    with Image.open(tmp_path / "m.gif") as im:
        assert im.n_frames == len(expected) and im.size in sizes
    assert_no_temporaries(tmp_path)


def test_every_frame_shows_its_stored_state():
    """Drawing the stored frames one by one: each map is that frame's total depth; the
    colour scale only grows and covers each frame."""
    case = load_case(CYLINDER, SMALL)
    frames = FextraStorageTracker(EVERY)
    res = run_model(case, "single_layer", tracker=frames)
    live = LayersPlotTracker(display="none", model="single_layer")
    live.initialize(res.state)
    tops = []
    for t, (data, fextra) in sorted(frames.snapshots.items()):
        live.draw(data, t, fextra)
        total = metrics_2d.total_depth(data)
        np.testing.assert_array_equal(_drawn(live.figure),
                                      np.where(total > DRY, total, np.nan))
        tops.append(live.figure._norm.vmax)
        assert tops[-1] >= total.max()
    assert tops == sorted(tops)
    live.discard()


def test_the_2d_live_plot_in_a_window_and_in_jupyter(monkeypatch):
    import IPython.display
    import matplotlib.pyplot as plt

    case = load_case(CYLINDER, SMALL)
    live = LayersPlotTracker(0.3, display="window")
    run_model(case, "single_layer", tracker=live)
    assert isinstance(live.figure, PlanFigure)
    assert plt.fignum_exists(live.figure.fig.number)  # left open for plt.show()
    live.figure.close()
    images = []
    monkeypatch.setattr(IPython.display, "display",
                        lambda obj, display_id=False: images.append(obj) or _Handle())
    run_model(case, "single_layer", tracker=LayersPlotTracker(0.3, display="jupyter"))
    assert len(images) == 1 and images[0].data[:4] == b"\x89PNG"


class _Handle:
    def update(self, obj):
        assert obj.data[:4] == b"\x89PNG"


@pytest.mark.skipif(ffmpeg_path() is None, reason="no ffmpeg (pip install imageio-ffmpeg)")
def test_run_writes_an_mp4_per_model_with_a_frame_per_interval(tmp_path, capsys):
    import imageio_ffmpeg

    movie = tmp_path / "cyl.mp4"
    assert main(["run", str(CYLINDER), *SETS, "--movie", str(movie), "--live-every",
                 str(EVERY), "--summary", str(tmp_path / "s.json"), "-q"]) == 0
    import json

    models = json.loads((tmp_path / "s.json").read_text())["models"]
    for path, model in ((movie, "two_layer"),
                        (tmp_path / "cyl.single_layer.mp4", "single_layer")):
        data = path.read_bytes()
        assert data[4:8] == b"ftyp", path  # an MP4 container
        t_end = models[model]["t_final"]
        n = len([t for t in np.arange(0, t_end, EVERY) if t < t_end - 1e-9]) + 1
        assert imageio_ffmpeg.count_frames_and_secs(str(path))[0] == n, model
    assert_no_temporaries(tmp_path)


def test_an_interrupted_2d_movie_leaves_nothing(tmp_path, monkeypatch, capsys):
    """Ctrl-C while the second model draws its movie and frames: the first model's
    finished movie and frames are discarded too; nothing is written."""
    draw = LayersPlotTracker.draw

    def interrupt(self, data, t, fextra=None):
        draw(self, data, t, fextra)
        if self.model == "single_layer" and len(self.times) == 2:
            os.kill(os.getpid(), signal.SIGINT)

    monkeypatch.setattr(LayersPlotTracker, "draw", interrupt)
    monkeypatch.chdir(tmp_path)
    assert main(["run", str(CYLINDER), *SETS, "--movie", "m.gif", "--frames", "fr",
                 "--live-every", str(EVERY), "--summary", "s.json", "-q"]) == 130
    err = capsys.readouterr().err
    assert err.strip().splitlines()[-1].endswith("; nothing written"), err
    assert list(tmp_path.iterdir()) == []
