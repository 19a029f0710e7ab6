"""The hand-written 2D loop of ``benchmarks/baseline_2d.py`` (what docs/two_d.md's cost
per cell update is measured against) does pdeflow's 2D single-layer scheme: the same
steps and the same depths to round-off on a small grid."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

import two_d_cost  # noqa: E402


def test_the_hand_written_2d_loop_gives_pdeflows_steps_and_depths():
    runs = two_d_cost.runs(16)
    mine, theirs = runs["single 2D"](), runs["baseline 2D"]()
    assert mine["steps"] == theirs["steps"] > 10
    h = mine["data"][0].reshape(16, 16)
    assert np.abs(h - 0.5).max() > 0.05  # the dam moved
    np.testing.assert_allclose(theirs["data"][0], h, rtol=0, atol=1e-12)
