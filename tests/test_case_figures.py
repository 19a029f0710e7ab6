"""The figures of ``pdeflow run``: a snapshot redrawn in place is the image of a new
figure, and the figure worker draws what it is sent or says why it could not."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
CASE = ROOT / "cases" / "paper_5_1_dam_break.toml"


@pytest.fixture(scope="module")
def runs():
    """Both models of the 5.1 case on a coarse grid."""
    from pdeflow.cases import load_case
    from pdeflow.simulate import run_model

    case = load_case(CASE, ["grid.dx=0.05"])
    return {m: run_model(case, m) for m in case.models}


def _pixels(fig) -> np.ndarray:
    fig.canvas.draw()
    return np.asarray(fig.canvas.buffer_rgba()).copy()


def test_a_snapshot_redrawn_in_place_is_the_image_of_a_new_figure(runs, tmp_path):
    from pdeflow.case_figures import SnapshotFigures, figure_jobs, snapshot_figure

    jobs = [job for job in figure_jobs(runs, tmp_path)
            if getattr(job[0], "__self__", None) is not None]
    assert len(jobs) >= 3
    series = jobs[0][0].__self__
    assert isinstance(series, SnapshotFigures)
    assert series.xlim is not None  # zoomed to the material (5.95 m of the 7 m domain)
    fresh = [_pixels(snapshot_figure(series.x, *args, series.title, series.coordinate,
                                     series.xlim))
             for _, args, _ in jobs]
    # in the jobs' order and backwards: what was drawn before does not show
    for order in (list(range(len(jobs))), list(range(len(jobs)))[::-1]):
        again = SnapshotFigures(series.x, series.title, series.coordinate, series.xlim)
        for i in order:
            assert np.array_equal(_pixels(again.draw(*jobs[i][1])), fresh[i]), i


def _fail() -> None:
    raise ValueError("no figure here")


def test_the_figure_worker_draws_what_it_is_sent_and_says_why_not(runs, tmp_path):
    from pdeflow.case_figures import run_figure_jobs
    from pdeflow.figure_worker import FigureError, FigureWorker

    worker = FigureWorker.start()
    if worker is None:
        pytest.skip("this process cannot fork (threads, or one core)")
    jobs = run_figure_jobs(runs, tmp_path / "out", tmp_path / "deposits.png")
    paths = worker.draw(jobs)
    assert paths == [path for _, _, path in jobs]
    assert all(p.is_file() and p.stat().st_size > 0 for p in paths)
    assert not worker.process.is_alive()

    failing = FigureWorker.start()
    with pytest.raises(FigureError, match="no figure here"):
        failing.draw([*jobs[:2], (_fail, (), tmp_path / "bad.png")])
    assert not (tmp_path / "bad.png").exists()

    idle = FigureWorker.start()  # a run that fails before its figures
    idle.close()
    assert idle.process.exitcode == 0


def test_the_deposit_figure_names_the_case_and_models_outlines_the_release_and_zooms(
        runs, tmp_path):
    """Titles read as text (no file or model names with underscores); the initial column
    is drawn; x ends 10 % beyond the deposit (the single layer's front, 5.95 m on this
    grid, below the 7 m domain)."""
    from pdeflow.case_figures import figure_jobs

    jobs = figure_jobs(runs, tmp_path)
    make, args, path = jobs[-1]
    assert path.name == "final_deposits.png"
    ax = make(*args).axes[0]
    title = ax.get_title()
    assert title.startswith("paper 5.1 dam break: final deposits")
    assert "two layers at rest at t = " in title and "single layer at rest" in title
    assert "_" not in title
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "initial state" in labels
    line = next(ln for ln in ax.get_lines() if ln.get_label() == "initial state")
    assert np.max(line.get_ydata()) == pytest.approx(2.0)  # H0 of the case, exactly set
    front = runs["single_layer"].summary["front_position"]
    assert ax.get_xlim()[1] == pytest.approx(1.1 * front, rel=0.02)  # a cell (0.05 m)
