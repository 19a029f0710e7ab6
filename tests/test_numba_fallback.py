"""The public path of the compile layer (``PDEFLOW_NUMBA_FALLBACK=1``, what a numba newer
than ``compiled.NEWEST_TESTED_NUMBA`` gets): plain ``numba.njit`` kernels compute what
the private hooks' kernels compute, and numba's disk cache serves a later process."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from numba import config

from pdeflow.numerics import compiled

ROOT = Path(__file__).parents[1]

pytestmark = pytest.mark.skipif(config.DISABLE_JIT, reason="nothing is compiled")

# test 5.1 (both models) through the command line, then which path compiled it and the
# disk-cache hits and misses of its kernels that close over no kernel (closures over
# kernels, such as the stepping loop and the source stages, are compiled in every
# process on the public path: numba's key for them changes)
RUN = r"""
import json, sys
from pdeflow.cli import main
from pdeflow.numerics import compiled
from pdeflow.numerics.kernel_identity import closes_over_kernels
assert main(["run", "cases/paper_5_1_dam_break.toml", "--final", sys.argv[1], "-q"]) == 0
cacheable = [k for k in compiled.kernels() if k.signatures
                and not closes_over_kernels(k.py_func)]
print("STATS" + json.dumps({
    "hooks": compiled.HOOKS is not None,
    "hits": sum(sum(k.stats.cache_hits.values()) for k in cacheable),
    "misses": sum(sum(k.stats.cache_misses.values()) for k in cacheable)}))
"""


def _run(out: Path, cache: Path | None, fallback: str) -> dict:
    """The script above in a fresh process; ``cache``: its NUMBA_CACHE_DIR (None:
    numba's default, the one the other tests fill)."""
    env = {**os.environ, "PYTHONPATH": str(ROOT), "PDEFLOW_NUMBA_FALLBACK": fallback}
    if cache is not None:
        env["NUMBA_CACHE_DIR"] = str(cache)
    proc = subprocess.run([sys.executable, "-c", RUN, str(out)], cwd=ROOT, env=env,
                          capture_output=True, text=True, timeout=1800)
    assert proc.returncode == 0, proc.stderr[-3000:]
    line = [x for x in proc.stdout.splitlines() if x.startswith("STATS")][0]
    return json.loads(line[len("STATS"):])


def test_the_public_path_computes_the_same_numbers_and_caches(tmp_path):
    """Test 5.1 run twice on the public path with an empty cache, then on the private
    hooks: the same final states of both models (the same numba code, compiled with
    other entry points and cache keys: equal to round-off, rtol 1e-13, and in fact
    bit-identical when measured), and the second public run loads every kernel it
    calls that closes over no kernel from the cache the first filled (kernels only called by kernels
    loaded whole are not loaded at all: fewer hits than the first run's misses)."""
    cache = tmp_path / "cache"
    first = _run(tmp_path / "public1.npz", cache, "1")
    second = _run(tmp_path / "public2.npz", cache, "1")
    assert not first["hooks"] and not second["hooks"]
    assert first["hits"] == 0 and first["misses"] > 0, first
    assert second["hits"] > 0 and second["misses"] == 0, second
    hooks = _run(tmp_path / "hooks.npz", None, "0")
    assert hooks["hooks"] is (compiled.HOOKS is not None)
    for suffix in ("", ".single_layer"):
        ref = np.load(tmp_path / f"hooks{suffix}.npz")
        for name in ("public1", "public2"):
            got = np.load(tmp_path / f"{name}{suffix}.npz")
            assert sorted(got.files) == sorted(ref.files)
            for key in ref.files:
                np.testing.assert_allclose(got[key], ref[key], rtol=1e-13, atol=0,
                                           err_msg=f"{name}{suffix}: {key}")
