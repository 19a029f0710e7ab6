"""Live plots of a running simulation (pdeflow.trackers.live.LayersPlotTracker): headless
frames and movies (.gif, .mp4), the final and the rest state drawn, in place in Jupyter,
in a pyplot window, and F_extra for two layers. Headless: tests/conftest.py forces Agg."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pdeflow.cases import load_case
from pdeflow.simulate import run_model
from pdeflow.trackers import FextraStorageTracker
from pdeflow.trackers.live import LayersPlotTracker, MovieError, ffmpeg_path

from .helpers import assert_no_temporaries

ROOT = Path(__file__).parents[1]
RITTER = ROOT / "cases" / "ritter_dam_break.toml"
COARSE = ["grid.cells=100", "output.snapshot_times=[]"]


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
    assert_no_temporaries(tmp_path)


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
    assert_no_temporaries(tmp_path)


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
