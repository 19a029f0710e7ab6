"""Grid search for the parameters of the paper's lost Table 1 against test 5.1.

Usage::

    python -m pdeflow.analysis.calibration [--case cases/paper_5_1_dam_break.toml]
        [--out calibration.jsonl] [--top 15]

Every combination of the grid below is run on the 5.1 case (two-layer model only) and
scored against what the paper reports: lower layer at rest at about 0.7 s, upper layer
just before 1.5 s, F_extra/rho1 below 2 m^2/s^2, run-out clearly shorter than the
single-layer one. The score is

    (t_lower - 0.7)^2 + (t_upper - 1.45)^2 + max(0, F - 2)^2 + max(0, R - 4.2)^2

with stop times in s (10 s if a layer never stops), F = max F_extra/rho1 and R the
run-out in m (4.2 m is 85 % of the single-layer run-out at phi_B = 30 deg). The best
rows are printed as a Markdown table; all rows go to ``--out`` (JSON lines).
"""

from __future__ import annotations

import argparse
import itertools
import json
from pathlib import Path
from typing import Any

from ..cases import load_case
from ..simulate import run_model

GRID: dict[str, list[float]] = {
    "phi_b_deg": [30, 34, 38, 40, 41, 42, 46],
    "k": [0.2, 0.5, 0.65, 0.8],
    "c": [0.003, 0.01, 0.03, 0.1],
    "du_reg": [0.0, 0.1, 0.3],
    "film_depth": [1e-4, 1e-3, 5e-3],
    "wedge_angle_deg": [60, 75],
}

TARGET_LOWER = 0.7
TARGET_UPPER = 1.45


def score(s: dict[str, Any]) -> float:
    lo = s["lower_stop_time"] if s["lower_stop_time"] is not None else 10.0
    up = s["upper_stop_time"] if s["upper_stop_time"] is not None else 10.0
    return ((lo - TARGET_LOWER) ** 2 + (up - TARGET_UPPER) ** 2
            + max(0.0, s["max_fextra_over_rho1"] - 2.0) ** 2
            + max(0.0, (s["runout"] or 0.0) - 4.2) ** 2)


def scan(case_path: str | Path, grid: dict[str, list[float]] = GRID) -> list[dict]:
    rows = []
    keys = list(grid)
    for values in itertools.product(*grid.values()):
        over = ["case.models=['two_layer']", "output.snapshot_times=[]"]
        for k, v in zip(keys, values, strict=True):
            section = "initial" if k == "wedge_angle_deg" else "two_layer"
            over.append(f"{section}.{k}={v}")
        s = run_model(load_case(case_path, over), "two_layer").summary
        row = dict(zip(keys, values, strict=True))
        row.update({k: s[k] for k in ("lower_stop_time", "upper_stop_time",
                                      "lower_slow_time", "upper_slow_time", "runout",
                                      "max_fextra_over_rho1", "max_fextra_x")})
        row["score"] = score(s)
        rows.append(row)
    rows.sort(key=lambda r: r["score"])
    return rows


def markdown(rows: list[dict], top: int) -> str:
    cols = list(rows[0])
    out = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    for r in rows[:top]:
        out.append("| " + " | ".join(
            "-" if r[c] is None else (f"{r[c]:.3g}" if isinstance(r[c], float) else str(r[c]))
            for c in cols) + " |")
    return "\n".join(out)


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--case", default="cases/paper_5_1_dam_break.toml")
    ap.add_argument("--out", default=None, help="write all rows as JSON lines")
    ap.add_argument("--top", type=int, default=15)
    args = ap.parse_args(argv)
    rows = scan(args.case)
    if args.out:
        Path(args.out).write_text("".join(json.dumps(r) + "\n" for r in rows))
    print(f"{len(rows)} parameter sets; best {args.top} by score:\n")
    print(markdown(rows, args.top))
    paper = [r for r in rows if r["du_reg"] == 0 and r["max_fextra_over_rho1"] < 2]
    print("\nBest sets with the paper's closure (du_reg = 0) and F_extra/rho1 < 2:\n")
    print(markdown(paper, 5))


if __name__ == "__main__":
    main()
