"""The app's float slider: its moves reach the server at once, and its read-out shows
every position's value (Bokeh's default read-out has two decimals)."""

from __future__ import annotations

import math
from typing import Any, ClassVar

import panel as pn

MAX_DECIMALS = 6
"""A slider's read-out shows at most this many decimals (an override is written with
6 significant digits, :func:`pdeflow.app.controls.toml_value`)."""


def decimals(*numbers: float) -> int:
    """The fewest decimals that write each of ``numbers`` exactly (0.25 -> 2, 5e-05 ->
    5, 100 -> 0), at most :data:`MAX_DECIMALS`."""
    def one(x: float) -> int:
        for d in range(MAX_DECIMALS + 1):
            # relative to the number: 0.1 * 10 is 1.0000000000000002 in binary
            if math.isclose(x * 10**d, round(x * 10**d), rel_tol=1e-9, abs_tol=1e-9):
                return d
        return MAX_DECIMALS
    return max(one(abs(float(x))) for x in numbers)


def readout_format(start: float, step: float, value: float = 0.0) -> str:
    """The numeral.js format of a slider's read-out: as many decimals as its positions
    ``start + k * step`` and its ``value`` (a case's own, between positions) have, so
    that no two positions read the same and none reads 0 but 0 (Bokeh's default, two
    decimals, showed a grain diameter of 0.0001 m as 0)."""
    d = decimals(start, step, value)
    return "0." + "0" * d if d else "0"


class Slider(pn.widgets.FloatSlider):
    """A float slider whose moves reach the server's callbacks at once, and whose
    read-out shows every position's value (:func:`readout_format`, kept up to date when
    its start, step or value change).

    Panel waits 50 ms after a widget's first event for more before it runs the callbacks;
    a slider's release (``value_throttled``) is the last event of a move, so that wait
    would only add to the time until the new picture."""

    _priority_changes: ClassVar[list[str]] = ["value", "value_throttled"]

    def __init__(self, **params: Any):
        super().__init__(**params)
        self._set_format()
        # an unchanged format is not sent again (param compares the strings)
        self.param.watch(lambda e: self._set_format(), ["start", "step", "value"])

    def _set_format(self) -> None:
        self.format = readout_format(self.start, self.step, self.value)
