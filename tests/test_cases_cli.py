"""Case files, validation messages, and the command line."""

import json
from pathlib import Path

import numpy as np
import pytest

from pdeflow.cases import CaseError, load_case
from pdeflow.cli import main

ROOT = Path(__file__).parents[1]
CASE = ROOT / "cases" / "paper_5_1_dam_break.toml"


@pytest.mark.parametrize("override, words", [
    ("two_layer.density_ratio=1.5", ["density_ratio", "(0, 1)"]),
    ("two_layer.k=1.0", ["k", "[0, 1)"]),
    ("two_layer.phi_int_deg=95", ["phi_int_deg", "(0, 90)"]),
    ("numerics.cfl=1.5", ["cfl", "(0, 1]"]),
    ("grid.dx=-0.1", ["grid.dx"]),
    ("grid.length=0", ["grid.length"]),
    ("two_layer.bogus=1", ["bogus", "two-layer"]),
    ("grid.colour=1", ["grid.colour", "allowed"]),
    ("case.t_end='long'", ["case.t_end", "float"]),
    ("initial.H0=-2", ["initial.H0"]),
])
def test_bad_values_are_rejected_with_their_name(override, words):
    with pytest.raises(CaseError) as err:
        load_case(CASE, [override])
    msg = str(err.value)
    assert str(CASE) in msg or CASE.name in msg
    for w in words:
        assert w in msg


def test_muscl_case_above_cfl_one_half_is_rejected():
    with pytest.raises(CaseError, match=r"numerics.cfl \(with reconstruction = 'muscl'\) "
                                        r"must lie in \(0, 0.5\]"):
        load_case(CASE, ["numerics.reconstruction='muscl'", "numerics.cfl=0.6"])
    assert load_case(CASE, ["numerics.reconstruction='muscl'", "numerics.cfl=0.5"]).cfl == 0.5


def test_case_files_are_data_not_code(tmp_path):
    p = tmp_path / "evil.toml"
    p.write_text('[case]\nname = "__import__(\'os\').system(\'echo hi\')"\n'
                 '[initial]\nshape = "column"\nL0 = 1\nH0 = 1\n')
    case = load_case(p)
    assert case.name.startswith("__import__")  # a plain string, never evaluated


def test_initial_profile_from_npz(tmp_path):
    n = 20
    np.savez(tmp_path / "init.npz", h1=np.full(n, 0.1), u1=np.zeros(n),
             h2=np.full(n, 0.2), u2=np.zeros(n))
    p = tmp_path / "c.toml"
    p.write_text('[grid]\nlength = 1.0\ncells = 20\n[initial]\nshape = "file"\n'
                 'path = "init.npz"\n')
    eq, state = load_case(p).make_state("two_layer")
    assert np.allclose(state.data[2], 0.2)
    np.savez(tmp_path / "init.npz", h1=np.full(n + 1, 0.1), u1=np.zeros(n),
             h2=np.full(n, 0.2), u2=np.zeros(n))
    with pytest.raises(CaseError, match="shape"):
        load_case(p).make_state("two_layer")


def test_cli_run_writes_summary_final_and_plot(tmp_path, capsys):
    out = tmp_path / "s.json"
    fin = tmp_path / "f.npz"
    png = tmp_path / "p.png"
    rc = main(["run", str(CASE), "--set", "grid.dx=0.1", "--summary", str(out),
               "--final", str(fin), "--plot", str(png)])
    assert rc == 0
    data = json.loads(out.read_text())
    two = data["models"]["two_layer"]
    for key in ("stop_time", "lower_stop_time", "upper_stop_time", "front_position",
                "runout", "max_fextra_over_rho1", "mass_relative_error", "steps",
                "wall_time_s"):
        assert key in two
    with np.load(fin) as f:
        assert set(f.files) >= {"x", "h1", "u1", "h2", "u2", "t"}
    with np.load(fin.with_name("f.single_layer.npz")) as f:
        assert set(f.files) >= {"x", "h", "u", "t"}
    assert png.stat().st_size > 1000
    assert "run-out" in capsys.readouterr().out


def test_cli_bad_override_is_a_clean_error(tmp_path, capsys):
    rc = main(["run", str(CASE), "--set", "two_layer.k=2", "--summary",
               str(tmp_path / "s.json")])
    assert rc == 2
    assert "k must lie in" in capsys.readouterr().err
    assert not (tmp_path / "s.json").exists()


def test_cli_blowup_is_a_clean_error_and_writes_nothing(tmp_path, capsys):
    """A velocity of 1e200 m/s overflows u^2 h in the first step: a genuine failure of
    the numerics (non-finite values), reported in one message, no partial files."""
    np.savez(tmp_path / "init.npz", h=np.array([0.5, 1.0, 0.2]),
             u=np.array([0.0, 1e200, 0.0]))
    p = tmp_path / "c.toml"
    p.write_text('[case]\nmodels = ["single_layer"]\nt_end = 1.0\n[grid]\nlength = 1.0\n'
                 'cells = 3\n[initial]\nshape = "file"\npath = "init.npz"\n')
    rc = main(["run", str(p), "--summary", str(tmp_path / "s.json"), "--store",
               str(tmp_path / "run.h5")])
    assert rc == 3
    err = capsys.readouterr().err
    assert err.startswith("pdeflow: simulation failed: fv-split blew up in step 1")
    assert "non-finite values" in err and "Traceback" not in err
    assert sorted(f.name for f in tmp_path.iterdir()) == ["c.toml", "init.npz"]


def test_cli_sweep_converge_compare(tmp_path):
    out = tmp_path / "sweep.json"
    rc = main(["sweep", str(ROOT / "cases" / "collapse_sweep.toml"), "--set", "grid.dx=0.02",
               "--set", "sweep.aspect_ratios=[2, 6]", "--summary", str(out), "-q"])
    assert rc == 0
    data = json.loads(out.read_text())
    for model in ("two_layer", "single_layer"):
        m = data["models"][model]
        assert len(m["points"]) == 2 and m["exponent"] > 0 and m["prefactor"] > 0
    conv = tmp_path / "conv.json"
    rc = main(["converge", str(CASE), "--levels", "2", "--model", "single_layer",
               "--set", "case.models=['single_layer']", "--set", "grid.dx=0.1",
               "--summary", str(conv)])
    assert rc == 0
    assert len(json.loads(conv.read_text())["levels"]) == 2
    rc = main(["compare", str(ROOT / "cases" / "ritter_dam_break.toml"), "--variants",
               "hll/first-order", "--grids", "50", "100", "--out-dir", str(tmp_path / "wp"),
               "--quiet", "--repeats", "1"])
    assert rc == 0
    assert (tmp_path / "wp" / "ritter_dam_break_workprecision.png").stat().st_size > 1000
