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
    fresh = [_pixels(snapshot_figure(series.x, *args, series.title, series.coordinate))
             for _, args, _ in jobs]
    # in the jobs' order and backwards: what was drawn before does not show
    for order in (list(range(len(jobs))), list(range(len(jobs)))[::-1]):
        again = SnapshotFigures(series.x, series.title, series.coordinate)
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
