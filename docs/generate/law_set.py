"""The planar two-layer law set (``cases/paper_5_2_two_layer_law.toml``) as ``--set``
overrides of another case, for the generators that run it on other geometries."""

from __future__ import annotations

from pathlib import Path

from pdeflow.cases import tomllib

LAW_CASE = Path(__file__).resolve().parents[2] / "cases" / "paper_5_2_two_layer_law.toml"


def law_set_overrides(path: Path = LAW_CASE, omit: tuple[str, ...] = ()) -> list[str]:
    """Every [two_layer] key of ``path`` but those in ``omit``, and its
    initial.wedge_angle_deg, as overrides."""
    data = tomllib.loads(path.read_text())
    out = [f"two_layer.{k}={v!r}" for k, v in data["two_layer"].items() if k not in omit]
    if "wedge_angle_deg" in data.get("initial", {}):
        out.append(f"initial.wedge_angle_deg={data['initial']['wedge_angle_deg']!r}")
    return out
