"""One Variant type: names parse and print back, bad names are named, cases round-trip."""

from __future__ import annotations

from pathlib import Path

import pytest

from pdeflow.cases import load_case
from pdeflow.variant import Scheme, Variant, VariantError

ROOT = Path(__file__).resolve().parents[1]

NAMES = ["hll/first-order", "rusanov/first-order", "ifcp/muscl/mc+strang",
         "hll/muscl/minmod", "hll/first-order@bound", "hll/first-order+strang@none",
         "mol-rk", "mol-euler", "mol-rk:rusanov/muscl/mc", "mol-euler@none"]


@pytest.mark.parametrize("name", NAMES)
def test_names_round_trip(name):
    v = Variant.parse(name)
    assert v.name == name and str(v) == name
    assert Variant.parse(v.name) == v


def test_defaults_are_left_out_of_names():
    assert Variant.parse("rusanov/muscl").limiter == "minmod"
    assert Variant.parse("rusanov/muscl").name == "rusanov/muscl/minmod"
    assert Variant.parse("hll/first-order+lie@exact").name == "hll/first-order"
    assert Variant().name == "hll/first-order"
    assert Variant.parse("mol-rk").solver == "runge-kutta"
    assert Variant.parse("mol-rk").is_mol and not Variant().is_mol


@pytest.mark.parametrize("bad, word", [
    ("hll", "FLUX/RECONSTRUCTION"), ("roe/first-order", "flux"),
    ("hll/first-order/mc", "limiter needs"), ("hll/muscl/vanleer", "limiter"),
    ("hll/first-order+godunov", "splitting"), ("hll/first-order@maybe", "hyperbolicity"),
    ("mol-bdf", "method of lines"), ("hll/weno", "reconstruction")])
def test_bad_names_say_what_is_wrong(bad, word):
    with pytest.raises(VariantError, match=word):
        Variant.parse(bad)


def test_method_of_lines_does_not_split():
    with pytest.raises(VariantError, match="splitting"):
        Variant(Scheme(splitting="strang"), solver="runge-kutta")


def test_a_case_round_trips_through_its_variant():
    case = load_case(ROOT / "cases" / "paper_5_1_dam_break.toml")
    assert case.variant == Variant()
    v = Variant.parse("ifcp/muscl/mc+strang@bound")
    applied = case.with_variant(v)
    assert applied.variant == v
    assert applied.cfl == case.cfl  # other numerics kept
    assert case.variant == Variant()  # the original is not touched
