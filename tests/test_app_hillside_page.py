"""The hillside page itself (Panel, no browser, no server): it shows the command line's
warnings for the case file it offers, its table is the runs' summaries, a refused run
is one line on the page, and a new run replaces the old one.

Outside a server the page has no periodic callback: the tests call its ``tick`` as the
server would every 66 ms."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

pytest.importorskip("panel", reason="the app needs the app extra")

from pdeflow.app.hillside import HillsidePage  # noqa: E402

from .helpers import cli_warnings  # noqa: E402

ROOT = Path(__file__).parents[1]
TIMEOUT_S = 300.0
"""Generous: the first run in a process loads (or compiles) the 2D kernels."""


def _play_to_the_end(page: HillsidePage) -> None:
    """Tick as the server would, until the page has drawn every frame and finished."""
    t0 = time.monotonic()
    while "done in" not in page.status.object and "the run" not in page.status.object:
        assert time.monotonic() - t0 < TIMEOUT_S, page.status.object
        page.tick()
        if page.run is not None and not page.run.finished:
            time.sleep(0.01)


@pytest.fixture(scope="module")
def page() -> HillsidePage:
    p = HillsidePage(ROOT / "cases")
    p.panel()
    return p


def test_the_page_warns_as_the_command_line_does(page, tmp_path, capsys):
    """A thick, mobile release runs off the grid's open end: the page's warnings box
    holds exactly the lines `pdeflow run` prints for the downloaded case file."""
    page.thickness.value, page.angle.value, page.cells.value = 5.0, 15.0, 40
    page.start()
    _play_to_the_end(page)
    assert page.run.status == "done"
    case_file = tmp_path / page.setup().file_name
    case_file.write_text(page._case_file().getvalue())
    expected = cli_warnings(case_file, [], tmp_path / "out", capsys)
    assert expected, "the scene was chosen to warn (material at the domain's end)"
    assert page.warnings.visible
    assert page.run.warnings == expected
    for line in expected:
        assert line.removeprefix("pdeflow: warning: ")[:40] in page.warnings.object


def test_the_table_holds_the_runs_summaries(page):
    page.thickness.value, page.angle.value, page.cells.value = 2.0, 25.0, 40
    page.start()
    _play_to_the_end(page)
    for summary in page.run.summaries.values():
        assert f"<td>{summary['runout']:.0f}</td>" in page.table.text
        assert f"<td>{summary['stop_time']:.1f}</td>" in page.table.text
    assert page.player.visible and page.player.end == page.run.frame_count() - 1


def test_a_release_outside_the_grid_is_refused_in_one_line(page):
    page.release.data = {"xs": [[5000.0, 5100.0, 5100.0]], "ys": [[10.0, 10.0, 90.0]]}
    before = page.run
    page.start()
    assert page.run is before  # nothing was started
    assert page.status.object.startswith("<b>cannot run this:</b>")
    assert "\n" not in page.status.object and "initial.vertices" in page.status.object
    page.load_terrain()  # the case's own release again


def test_a_new_run_cancels_the_one_before(page):
    page.thickness.value, page.cells.value = 2.0, 200
    page.start()
    first = page.run
    page.thickness.value = 3.0
    page.start()
    assert first.wait(TIMEOUT_S)
    assert first.status in ("stopped", "done")  # cancelled, unless it had ended already
    assert page.run is not first
    _play_to_the_end(page)
    assert page.run.setup.thickness == 3.0 and page.run.status == "done"
