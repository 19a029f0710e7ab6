"""The generators' shared publishing step (docs/generate/run_cache.py): numbers equal but
for round-off leave the tracked numbers.json and page as they are; real changes rewrite
them."""

from __future__ import annotations

import json
import time

import pytest

from tests.helpers import generator_modules


@pytest.fixture(scope="module")
def run_cache():
    with generator_modules("run_cache") as (module,):
        yield module


def test_same_numbers_tells_round_off_from_change(run_cache):
    same = run_cache.same_numbers
    # the two values of one fit on two processors (issue: 1 failed on a fresh machine)
    assert same({"H": [1.0817952306268672]}, {"H": [1.0817952306268674]})
    assert same([0.0, "cone", True], [1e-17, "cone", True])
    assert not same({"H": [1.0]}, {"H": [1.0001]})
    assert not same({"H": 1.0}, {"R": 1.0})
    assert not same([1.0, 2.0], [1.0])
    assert not same("cone", "truncated cone")
    assert not same(True, 1)


def render(numbers):
    return f"# page\n\nH = {numbers['H']:.4g} ({numbers['generator_wall_s']} s)\n"


def test_publish_keeps_files_that_only_round_off_would_change(run_cache, tmp_path):
    data, page = tmp_path / "numbers.json", tmp_path / "page.md"
    run_cache.publish({"H": 1.0817952306268672}, time.perf_counter(), data, page, render)
    before = data.read_bytes(), page.read_bytes()
    # a later call: other wall time, the last digit of the fit moved
    run_cache.publish({"H": 1.0817952306268674}, time.perf_counter() - 5.0, data, page,
                      render)
    assert (data.read_bytes(), page.read_bytes()) == before
    run_cache.publish({"H": 1.2}, time.perf_counter(), data, page, render)
    assert json.loads(data.read_text())["H"] == 1.2
    assert "H = 1.2 " in page.read_text()


def test_publish_rewrites_a_page_that_is_not_the_rendering(run_cache, tmp_path):
    data, page = tmp_path / "numbers.json", tmp_path / "page.md"
    run_cache.publish({"H": 2.0}, time.perf_counter(), data, page, render)
    page.write_text("edited by hand\n")
    run_cache.publish({"H": 2.0}, time.perf_counter(), data, page, render)
    assert page.read_text().startswith("# page")


def test_publish_gives_redrawn_figures_their_bytes_back(run_cache, tmp_path):
    data, page, fig = tmp_path / "numbers.json", tmp_path / "page.md", tmp_path / "f.png"
    fig.write_bytes(b"first drawing")
    run_cache.publish({"H": 1.0}, time.perf_counter(), data, page, render)
    before = run_cache.snapshot([fig, tmp_path / "absent.png"])
    fig.write_bytes(b"redrawn with a line moved by round-off")
    run_cache.publish({"H": 1.0 + 1e-15}, time.perf_counter(), data, page, render, before)
    assert fig.read_bytes() == b"first drawing"
    fig.write_bytes(b"redrawn, numbers changed")
    run_cache.publish({"H": 3.0}, time.perf_counter(), data, page, render, before)
    assert fig.read_bytes() == b"redrawn, numbers changed"


@pytest.fixture(scope="module")
def provenance():
    with generator_modules("provenance") as (module,):
        yield module


def test_inputs_of_a_page_are_its_generator_cases_and_kernels(provenance):
    listing = ["docs/generate/convergence.py", "docs/generate/rheology.py",
               "cases/paper_5_1_dam_break.toml", "cases/ritter_dam_break.toml",
               "pdeflow/numerics/pvm.py", "pdeflow/models/two_layer/friction.py",
               "pdeflow/cli.py", "pdeflow/app/controls.py"]
    assert provenance.input_files("docs/convergence.md", listing) == [
        "cases/paper_5_1_dam_break.toml", "docs/generate/convergence.py",
        "pdeflow/models/two_layer/friction.py", "pdeflow/numerics/pvm.py"]


def test_a_stamped_page_goes_stale_when_an_input_changes(provenance, tmp_path):
    """A tree outside git: the stamp records the inputs; editing a kernel or the
    generator makes the page stale, editing the CLI does not."""
    for name in ("docs/generate/convergence.py", "pdeflow/numerics/pvm.py", "pdeflow/cli.py",
                 "cases/paper_5_1_dam_break.toml"):
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text(f"# {name}\n")
    record = tmp_path / "generated.json"
    provenance.stamp(["docs/convergence.md"], root=tmp_path, record=record)
    assert "docs/convergence.md" not in provenance.stale(tmp_path, record)
    (tmp_path / "pdeflow/cli.py").write_text("# a new option\n")
    assert "docs/convergence.md" not in provenance.stale(tmp_path, record)
    (tmp_path / "pdeflow/numerics/pvm.py").write_text("# another flux\n")
    assert "docs/convergence.md" in provenance.stale(tmp_path, record)
    with pytest.raises(SystemExit, match="not a generated page"):
        provenance.stamp(["docs/model.md"], root=tmp_path, record=record)


def test_every_generated_page_is_registered(provenance):
    """A page that says it is generated has its inputs listed, and the record names
    only registered pages."""
    root = provenance.ROOT
    for page in (root / "docs").glob("*.md"):
        head = page.read_text().split("\n## ")[0]
        if "Generated by" in head and page.name != "architecture.md":
            assert f"docs/{page.name}" in provenance.PAGES, page.name
    assert set(provenance.read_record()) <= set(provenance.PAGES)
