"""``NUMBA_DISABLE_JIT=1`` (numba's switch for debugging kernels as Python) runs a case.

The kernels then run as the Python functions they are written as: the same arithmetic,
so the numbers agree with the compiled run to round-off (numba's ``math`` functions and
Python's may differ in the last bit).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CASE = ROOT / "cases" / "paper_5_1_dam_break.toml"


def _summary(tmp_path: Path, name: str, env: dict[str, str]) -> dict:
    out = tmp_path / f"{name}.json"
    subprocess.run([sys.executable, "-m", "pdeflow", "run", str(CASE), "-q",
                    "--set", "grid.cells=40", "--summary", str(out)],
                   check=True, cwd=tmp_path, env=env, capture_output=True, text=True)
    return json.loads(out.read_text())["models"]


def test_a_case_runs_without_jit_and_agrees_with_the_compiled_run(tmp_path):
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    env.pop("NUMBA_DISABLE_JIT", None)
    compiled = _summary(tmp_path, "jit", env)
    python = _summary(tmp_path, "nojit", {**env, "NUMBA_DISABLE_JIT": "1"})
    assert python.keys() == compiled.keys() == {"two_layer", "single_layer"}
    for model, numbers in compiled.items():
        for key, value in numbers.items():
            if isinstance(value, float) and "wall" not in key:
                # mass errors are round-off themselves: compared absolutely
                assert abs(python[model][key] - value) <= 1e-12 * max(1.0, abs(value)), \
                    (model, key)
            elif "wall" not in key:
                assert python[model][key] == value, (model, key)
