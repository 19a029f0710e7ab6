"""A bed written as an expression in the case file (issue 37: "bed from an analytic
expression in the case file"): ``terrain.expression``, parsed once, arithmetic and
numpy's elementwise functions only, with one-line errors before any work."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pdeflow.cases import Case
from pdeflow.simulate import RunWarning, run_model
from pdeflow.terrain import bed_expression
from pdeflow.terrain import topographies as topo
from tests.test_terrain_cases import base, refused

PLANE = "500 - tan(30 * (pi / 180)) * x"
"""the inclined plane of :func:`tests.test_terrain_cases.base` as an expression"""


def test_an_expression_is_evaluated_on_arrays_of_points():
    x, y = np.meshgrid(np.linspace(0, 10, 4), np.linspace(-2, 2, 3), indexing="ij")
    z = bed_expression("100 - 2 * x + where(y > 0, y**2, 0) + hypot(x, y) % 3")(x, y)
    np.testing.assert_allclose(z, 100 - 2 * x + np.where(y > 0, y**2, 0)
                               + np.hypot(x, y) % 3, rtol=1e-15)
    assert bed_expression(" 42 ")(x, y).shape == x.shape  # a constant takes the shape


@pytest.mark.parametrize("text, words", [
    ("__import__('os').system('true')", ["attribute", "not allowed"]),
    ("__import__('os')", ["function '__import__'", "not allowed"]),
    ("x.real", ["attribute", "not allowed"]),
    ("x[0]", ["subscript", "not allowed"]),
    ("(lambda: 1)()", ["lambda", "not allowed"]),
    ("np.sin(x)", ["attribute"]),
    ("z + 1", ["name 'z'", "x, y, pi, e"]),
    ("sin(x, out=y)", ["positional"]),
    ("'high' * x", ["'high' is not a number"]),
    ("x +", ["does not parse"]),
    ("", ["expression in x and y"]),
    ("x if y else 0", ["ifexp", "not allowed"]),
    ("x == y", ["eq", "not allowed"]),
])
def test_anything_but_arithmetic_is_refused_in_one_line(text, words):
    with pytest.raises(ValueError) as err:
        bed_expression(text)
    message = str(err.value)
    assert "\n" not in message
    for word in words:
        assert word in message, (word, message)


def test_the_case_files_expression_gives_the_topographys_bed_and_run():
    """The inclined plane of the tests' base case written as an expression gives its
    corners (to round-off: numpy's tan against math's, pi / 180 against radians) and
    its run's summary."""
    named = Case.from_dict(base())
    written = Case.from_dict(base(terrain={"bed": None, "topography": None,
                                           "expression": PLANE}))
    corners = written.terrain_corners()
    np.testing.assert_allclose(corners, named.terrain_corners(), rtol=1e-14, atol=0)
    x = 20.0 * np.arange(11)
    assert corners[:, 0] == pytest.approx(500 - math.tan(math.radians(30)) * x, rel=1e-14)
    with pytest.warns(RunWarning):  # (the material reaches the sides: a small grid)
        a = run_model(named, "single_layer").summary
    with pytest.warns(RunWarning):
        b = run_model(written, "single_layer").summary
    # round-off in the bed moves the numbers by round-off (stops and steps alike)
    assert (b["steps"], b["at_rest"]) == (a["steps"], a["at_rest"])
    for key in ("runout", "front_position", "max_depth", "max_speed", "affected_area",
                "lateral_spread", "travel_angle"):
        assert b[key] == pytest.approx(a[key], rel=1e-9, abs=1e-12), key


@pytest.mark.parametrize("terrain, words", [
    ({"expression": "500 - 0.5 * x"}, ["terrain.bed", "terrain.expression", "keep one"]),
    ({"bed": None, "expression": "500 - 0.5 * x"}, ["terrain.topography",
                                                   "terrain.expression"]),
    ({"bed": None, "topography": None, "expression": "500 - import_(x)"},
     ["terrain.expression", "function 'import_'"]),
    ({"bed": None, "topography": None, "expression": "100 + log(x)"},
     ["terrain.expression", "not finite", "x = 0"]),
    ({"bed": None, "topography": None, "expression": 5.0}, ["terrain.expression", "str"]),
])
def test_a_bad_expression_in_a_case_is_one_line_naming_the_key(terrain, words):
    refused(base(terrain=terrain), *words)


def test_the_topographies_can_be_written_as_expressions():
    """A topography's own equation (the parabola's, AvaFrame's PF) as an expression
    gives its bed at the corners."""
    c, f = 1000.0, 1000.0 / math.tan(math.radians(34.0))
    text = f"where(x < {f!r}, {c!r} * (1 - x / {f!r})**2, 0)"
    x, y = np.meshgrid(np.linspace(0, 2000, 21), np.linspace(-300, 300, 7), indexing="ij")
    np.testing.assert_allclose(bed_expression(text)(x, y), topo.parabola(x, y),
                               rtol=1e-12, atol=1e-9)
