"""The outputs of a work-precision study (:func:`pdeflow.analysis.workprecision.compare`):
a Markdown table, a work-precision diagram and the JSON of the rows, and the result
they are made of (:class:`CompareResult`, below the study that fills it)."""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from ..variant import Variant


@dataclass
class CompareResult:
    """Rows of a work-precision study and the files written."""

    case: str
    t: float
    rows: list[dict[str, Any]]
    files: dict[str, str] = field(default_factory=dict)

    def to_json(self) -> dict[str, Any]:
        return asdict(self)


def _fmt(v: Any, spec: str) -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "-"
    return format(v, spec)


def units(result: CompareResult, tex: bool = False) -> tuple[str, str]:
    """The units of the L1 errors of depth and momentum: per unit width on a 1D grid
    (m^2, m^3/s), over the area on a 2D one (m^3, m^4/s; its rows have ``cells_y``);
    ``tex``: as matplotlib's mathtext."""
    two_d = bool(result.rows) and "cells_y" in result.rows[0]
    area, length = (3, 4) if two_d else (2, 3)
    if tex:
        return f"m$^{area}$", f"m$^{length}$/s"
    return f"m^{area}", f"m^{length}/s"


def _cells(row: dict[str, Any]) -> str:
    return f"{row['cells']}x{row['cells_y']}" if "cells_y" in row else str(row["cells"])


def markdown_table(result: CompareResult) -> str:
    """The rows of ``result`` as a Markdown table."""
    depth, momentum = units(result)
    lines = [f"| model | variant | cells | L1 depth [{depth}] | L1 momentum [{momentum}] | "
             "order | wall [ms] | steps | status |",
             "|---|---|---:|---:|---:|---:|---:|---:|---|"]
    for r in result.rows:
        status = r["status"] if r["status"] == "ok" else f"{r['status']}: {r['note']}"
        lines.append(
            f"| {r['model']} | {r['variant']} | {_cells(r)} | {_fmt(r['err_h'], '.3e')} | "
            f"{_fmt(r['err_hu'], '.3e')} | {_fmt(r['order_h'], '.2f')} | "
            f"{_fmt(r['wall_s'] * 1e3, '.3g')} | {r['steps']} | {status} |")
    return "\n".join(lines) + "\n"


def plot(result: CompareResult, path: str | Path) -> Path:
    """Work-precision diagram: L1 depth and momentum errors against the median wall
    time, log-log, one line per variant, one column per model."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    models = list(dict.fromkeys(r["model"] for r in result.rows))
    variants = list(dict.fromkeys(r["variant"] for r in result.rows))
    fig, axes = plt.subplots(2, len(models), figsize=(5.5 * len(models), 8), squeeze=False)
    markers = "osD^v<>phX*"
    depth, momentum = units(result, tex=True)
    for j, model in enumerate(models):
        for i, (key, label) in enumerate((("err_h", f"L1 depth error [{depth}]"),
                                          ("err_hu", f"L1 momentum error [{momentum}]"))):
            ax = axes[i, j]
            for k, v in enumerate(variants):
                rs = [r for r in result.rows if r["model"] == model and r["variant"] == v
                      and r["status"] == "ok" and r[key] > 0]
                if not rs:
                    continue
                ls = "--" if "strang" in v else (":" if Variant.parse(v).is_mol else "-")
                ax.loglog([r["wall_s"] for r in rs], [r[key] for r in rs],
                          marker=markers[k % len(markers)], ls=ls, label=v)
            ax.set_xlabel("median wall time of the compiled run [s]")
            ax.set_ylabel(label)
            ax.set_title(f"{result.case}: {model}, t = {result.t:g} s")
            ax.grid(True, which="both", alpha=0.3)
        axes[0, j].legend(fontsize=8)
    fig.tight_layout()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def write_outputs(result: CompareResult, out_dir: Path) -> dict[str, str]:
    """Write ``<case>_workprecision.json``, ``.md`` and ``.png`` into ``out_dir``."""
    out_dir.mkdir(parents=True, exist_ok=True)
    stem = out_dir / f"{result.case}_workprecision"
    png = plot(result, stem.with_suffix(".png"))
    md = stem.with_suffix(".md")
    md.write_text(f"# Work precision: {result.case}, t = {result.t:g} s\n\n"
                  + markdown_table(result))
    result.files = {"png": str(png), "md": str(md), "json": str(stem.with_suffix(".json"))}
    stem.with_suffix(".json").write_text(json.dumps(result.to_json(), indent=1,
                                                    default=float))
    return result.files


