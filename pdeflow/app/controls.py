"""The case and its parameters as widgets, and the ``--set`` overrides they stand for.

Every page that runs a case (dam break, run-out law) reads its sliders as the overrides
``section.key=value`` of ``pdeflow run CASE --set ...`` and passes them to
:func:`pdeflow.cases.load_case`: what a page shows is what the command line (printed
under it) or the Python API gives for the same overrides. Values are in the units of
the case files: m, deg, and dimensionless.
"""

from __future__ import annotations

import math
import shlex
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import panel as pn

from .. import systems
from ..analysis.workprecision import DEFAULT_VARIANTS
from ..cases import Case, CaseError, load_case
from ..models.friction_laws import LAWS, FrictionLawParameters
from ..variant import Variant
from .slider import Slider  # the pages import it from here

GEOMETRIES = ("planar", "axisymmetric")
"""grid.geometry choices: a slope of unit width, or a column collapsing radially"""
DEFAULT_LAW = FrictionLawParameters.friction_law
"""The law selected before a case names one (the models' default, Coulomb's); the
laws offered are those registered, :data:`pdeflow.models.friction_laws.LAWS`."""
CLOSURES = ("paper", "relaxed")
"""The exchange closures offered (a case with another one adds it to the choice)."""
SCHEMES = tuple(v for v in DEFAULT_VARIANTS if not Variant.parse(v).is_mol)
"""fv-split variants offered, by the names of ``pdeflow compare`` (FLUX/REC[/LIM][+SPLIT])."""
PRESENTED = ("H0", "L0", "slope", "phi_b_two", "phi_b_single", "length", "t_end")
"""The sliders presentation mode keeps (the others, and the closure, geometry, law and
scheme choices, are hidden: a lecture needs the physics, not every knob)."""
MAX_CELLS = 20_000
"""Larger grids would keep the server busy for seconds per slider move: refused."""


@dataclass(frozen=True)
class Knob:
    """A slider for one or more case keys that always take the same value."""

    name: str
    """widget name (also its CSS class ``pdeflow-<name>``, used by the browser tests)"""
    label: str
    keys: tuple[str, ...]
    """the case keys it sets, ``section.key``"""
    start: float
    end: float
    step: float
    models: tuple[str, ...] = ("two_layer",)
    """the slider is enabled when the case runs one of these models"""
    column_only: bool = False
    """only for column cases (H0, L0)"""
    laws: tuple[str, ...] = ()
    """enabled only when the chosen basal friction law is one of these (() = any)"""
    around_case: tuple[float, float] | None = None
    """(low, high) factors: the slider runs from low to high times the case's own value,
    in steps of about ``step`` times it (a case of 0.3 m and one of 7 m both get a
    useful range); None: from ``start`` to ``end`` in steps of ``step``"""
    in_sweep: bool = True
    """offered on the run-out page too (a sweep sets its own domain and end time)"""


KNOBS = (
    Knob("H0", "column height H0 [m]", ("initial.H0",), 0.25, 4.0, 0.05,
         ("two_layer", "single_layer"), column_only=True),
    Knob("L0", "column length L0 [m]", ("initial.L0",), 0.25, 2.0, 0.05,
         ("two_layer", "single_layer"), column_only=True),
    Knob("slope", "bed slope θ [deg]", ("two_layer.theta_deg", "single_layer.theta_deg"),
         0.0, 35.0, 1.0, ("two_layer", "single_layer")),
    Knob("length", "domain length [m]", ("grid.length",), 2.0, 60.0, 0.25,
         ("two_layer", "single_layer"), around_case=(1.0, 8.0), in_sweep=False),
    Knob("t_end", "end time t_end [s]", ("case.t_end",), 1.0, 20.0, 0.1,
         ("two_layer", "single_layer"), around_case=(1.0, 4.0), in_sweep=False),
    Knob("density_ratio", "density ratio r = ρ1/ρ2", ("two_layer.density_ratio",),
         0.3, 0.95, 0.01),
    Knob("phi_int", "interface friction φ_int [deg]", ("two_layer.phi_int_deg",),
         15.0, 45.0, 1.0),
    Knob("phi_b_two", "basal friction φ_B, two layers [deg]", ("two_layer.phi_b_deg",),
         20.0, 50.0, 1.0),
    Knob("phi_b_single", "basal friction φ_B, single layer [deg]",
         ("single_layer.phi_b_deg",), 15.0, 45.0, 1.0, ("single_layer",)),
    Knob("k", "friction reduction k", ("two_layer.k",), 0.0, 0.95, 0.05),
    Knob("c", "collisional coefficient c", ("two_layer.c",), 0.0, 3.0, 0.01),
    *(Knob(name, label, (f"two_layer.{key}", f"single_layer.{key}"), lo, hi, step,
           ("two_layer", "single_layer"), laws=laws)
      for name, label, key, lo, hi, step, laws in (
          ("delta1", "δ1, μ at vanishing rate [deg]", "delta1_deg", 10.0, 32.0, 0.1,
           ("pouliquen", "mu_i")),
          ("delta2", "δ2, μ at large rate [deg]", "delta2_deg", 21.0, 45.0, 0.1,
           ("pouliquen", "mu_i")),
          ("pouliquen_L", "Pouliquen L [m]", "pouliquen_L", 1e-4, 5e-3, 5e-5,
           ("pouliquen",)),
          ("pouliquen_beta", "Pouliquen β", "pouliquen_beta", 0.05, 0.5, 0.001,
           ("pouliquen",)),
          ("mu_i_I0", "μ(I) I0", "mu_i_I0", 0.05, 1.0, 0.001, ("mu_i",)),
          ("grain_diameter", "grain diameter d [m]", "grain_diameter", 1e-4, 5e-3, 5e-5,
           ("mu_i",)),
          ("voellmy_mu", "Voellmy μ", "voellmy_mu", 0.0, 0.8, 0.005, ("voellmy",)),
          ("voellmy_xi", "Voellmy ξ [m/s²]", "voellmy_xi", 100.0, 10000.0, 100.0,
           ("voellmy",)))),
)


def served() -> bool:
    """True inside a served session (callbacks can be scheduled on its event loop)."""
    doc = pn.state.curdoc
    return doc is not None and doc.session_context is not None


def find_case_dir(explicit: str | Path | None = None) -> Path:
    """The directory of case files: ``explicit``, else ./cases, else the repository's.

    Raises CaseError (one line) if there is none: the case files are not installed with
    the package, the app runs from a clone (or is given ``--cases DIR``).
    """
    if explicit is not None:
        path = Path(explicit)
        if not path.is_dir() or not any(path.glob("*.toml")):
            raise CaseError(f"--cases {path}: not a directory with case files (*.toml)")
        return path
    for path in (Path.cwd() / "cases", Path(__file__).resolve().parents[2] / "cases"):
        if (path / "paper_5_1_dam_break.toml").is_file():
            return path
    raise CaseError("no case files found: run pdeflow app in the repository (next to "
                    "cases/) or give --cases DIR")


def list_cases(case_dir: Path, need: Callable[[Case], bool] = lambda c: True
               ) -> dict[str, Path]:
    """Case files in ``case_dir`` that load and satisfy ``need``, by file name."""
    out = {}
    for path in sorted(case_dir.glob("*.toml")):
        try:
            case = load_case(path)
        except CaseError:
            continue  # not runnable as it is: not offered
        if need(case) and not case.is_2d and case.cells <= MAX_CELLS:  # the app is 1D
            out[path.name] = path
    return out


def is_column(case: Case) -> bool:
    return case.initial.get("shape") == "column"


def case_value(case: Case, key: str) -> Any:
    """The value ``section.key`` has in ``case``, with the models' documented defaults."""
    section, name = key.split(".", 1)
    if section == "initial":
        return case.initial.get(name)
    if section in systems.names():
        cls = systems.get(section).parameters_class
        return getattr(cls.from_dict(case.data.get(section, {})), name)
    return case.data.get(section, {}).get(name)


def _law_models(case: Case) -> list[str]:
    """The case's models that have a basal friction law (``friction_law``)."""
    return [m for m in case.models
            if hasattr(systems.get(m).parameters_class, "friction_law")]


def case_law(case: Case) -> str:
    """The basal friction law of the case's first model that has one (else Coulomb)."""
    models = _law_models(case)
    return str(case_value(case, f"{models[0]}.friction_law")) if models else DEFAULT_LAW


def case_scheme(case: Case) -> str:
    """The case's fv-split variant by its ``pdeflow compare`` name."""
    return case.make_pde(case.models[0]).scheme.name


def toml_value(value: Any) -> str:
    """``value`` as the right-hand side of an override (floats to 6 digits)."""
    if isinstance(value, str):
        return repr(value)
    if isinstance(value, float):
        return f"{value:.6g}"
    return str(value)


def command_line(case_path: Path, overrides: Sequence[str]) -> str:
    """The ``pdeflow run`` command that runs the same case with the same overrides."""
    try:
        shown = case_path.resolve().relative_to(Path.cwd())
    except ValueError:
        shown = case_path
    args = ["pdeflow", "run", str(shown)]
    for item in overrides:
        args += ["--set", item]
    return " ".join(_quote(a) for a in args)


def _quote(arg: str) -> str:
    """``arg`` for a POSIX shell, readably: a TOML string value in single quotes goes in
    double quotes (``"two_layer.exchange_closure='relaxed'"``), where nothing else in it
    is special to the shell, instead of shlex's '...'"'"'...'"'"' form."""
    quoted = shlex.quote(arg)
    if quoted != arg and "'" in arg and not any(c in arg for c in '"$`\\!'):
        return f'"{arg}"'
    return quoted


class ParameterControls:
    """A case selector, the sliders of :data:`KNOBS` and the closure, geometry and
    scheme choices.

    ``on_change()`` is called after the user changed the case, released a slider, or
    picked a closure or scheme; never while :meth:`set_case` puts a case's own values
    into the widgets.

    Args:
        cases: selectable case files by name.
        default: the name selected first.
        on_change: called without arguments after a change by the user.
        knobs: the sliders to show (default: all of :data:`KNOBS`).
    """

    def __init__(self, cases: dict[str, Path], default: str,
                 on_change: Callable[[], None], knobs: Sequence[Knob] = KNOBS):
        self.cases = cases
        self.on_change = on_change
        self.knobs = list(knobs)
        self._quiet = False
        self._present = False
        # the selects as wide as the side bar (Panel's default, 300 px, is wider)
        self.case_select = pn.widgets.Select(label="case file", options=list(cases),
                                             value=default, css_classes=["pdeflow-case"],
                                             sizing_mode="stretch_width")
        self.sliders = {k.name: Slider(
            label=k.label, start=k.start, end=k.end, step=k.step, value=k.start,
            css_classes=[f"pdeflow-{k.name}"], sizing_mode="stretch_width")
            for k in self.knobs}
        self.closure = pn.widgets.RadioButtonGroup(
            label="exchange closure", options=list(CLOSURES), value="paper",
            css_classes=["pdeflow-closure"])
        self.geometry = pn.widgets.RadioButtonGroup(
            label="geometry", options=list(GEOMETRIES), value="planar",
            css_classes=["pdeflow-geometry"])
        self.law = pn.widgets.Select(label="basal friction law", options=list(LAWS),
                                     value=DEFAULT_LAW, css_classes=["pdeflow-law"],
                                     sizing_mode="stretch_width")
        self.scheme = pn.widgets.Select(label="scheme (flux/reconstruction[/limiter]"
                                        "[+splitting])", options=list(SCHEMES),
                                        value=SCHEMES[0], css_classes=["pdeflow-scheme"],
                                        sizing_mode="stretch_width")
        self.case: Case = load_case(cases[default])
        self.set_case(self.case)
        self.case_select.param.watch(self._case_changed, "value")
        for s in self.sliders.values():
            s.param.watch(self._changed, "value_throttled")
        self.closure.param.watch(self._changed, "value")
        self.geometry.param.watch(self._changed, "value")
        self.law.param.watch(self._law_changed, "value")
        self.scheme.param.watch(self._changed, "value")

    # --- the case's own values into the widgets -------------------------------------------
    def set_case(self, case: Case) -> None:
        """Show ``case``'s values; enable what applies to its models and shape."""
        self._quiet = True
        try:
            law = case_law(case)
            self.law.options = list(dict.fromkeys([*LAWS, law]))
            self.law.value = law
            for k in self.knobs:
                s = self.sliders[k.name]
                applies = (any(m in case.models for m in k.models)
                           and (is_column(case) or not k.column_only))
                s.disabled = not applies or bool(k.laws and law not in k.laws)
                keys = _keys_of_case(k, case)
                value = case_value(case, keys[0]) if applies and keys else None
                if value is None:
                    continue
                value = float(value)
                if k.around_case:
                    _range_around(s, k, value, case)
                elif k.column_only:  # around the case's own column, inside its domain
                    s.start = _round_step(min(k.start, value / 4), k.step)
                    end = max(k.end, 2 * value)
                    if k.name == "L0":
                        end = min(end, case.length / 2)
                    s.end = _round_step(end, k.step)
                else:
                    s.start = min(k.start, value)
                    s.end = max(k.end, value)
                s.value = value
            two = "two_layer" in case.models
            closure = str(case_value(case, "two_layer.exchange_closure"))
            self.closure.options = list(dict.fromkeys([*CLOSURES, closure]))
            self.closure.value = closure
            self.closure.disabled = not two
            self.geometry.value = case.geometry
            # the axis is a wall at x = 0: a case starting elsewhere or open there has
            # no axisymmetric counterpart
            self.geometry.disabled = not (case.bc[0] == "wall" and case.x_start == 0.0)
            scheme = case_scheme(case)
            self.scheme.options = list(dict.fromkeys([*SCHEMES, scheme]))
            self.scheme.value = scheme
            self.scheme.disabled = case.solver != "fv-split"
        finally:
            self._quiet = False

    # --- the widgets' values as overrides -------------------------------------------------
    def overrides(self) -> list[str]:
        """``section.key=value`` for every value that differs from the case's own."""
        case = self.case
        out = []
        for k in self.knobs:
            s = self.sliders[k.name]
            if s.disabled:
                continue
            for key in _keys_of_case(k, case):
                own = case_value(case, key)
                if own is None or not math.isclose(s.value, float(own),
                                                   abs_tol=s.step / 1000):
                    out.append(f"{key}={toml_value(float(s.value))}")
        if not self.closure.disabled and self.closure.value != case_value(
                case, "two_layer.exchange_closure"):
            out.append(f"two_layer.exchange_closure={toml_value(self.closure.value)}")
        if not self.geometry.disabled and self.geometry.value != case.geometry:
            out.append(f"grid.geometry={toml_value(self.geometry.value)}")
        for m in _law_models(case):
            if self.law.value != case_value(case, f"{m}.friction_law"):
                out.append(f"{m}.friction_law={toml_value(self.law.value)}")
        if not self.scheme.disabled and self.scheme.value != case_scheme(case):
            own = case.variant.numerics()
            for key, value in Variant.parse(self.scheme.value).numerics().items():
                if own.get(key) != value:
                    out.append(f"numerics.{key}={toml_value(value)}")
        return out

    @property
    def case_path(self) -> Path:
        return self.cases[self.case_select.value]

    def load(self, extra: Sequence[str] = ()) -> Case:
        """The selected case with the widgets' overrides (and ``extra`` ones) applied."""
        return load_case(self.case_path, [*self.overrides(), *extra])

    # --- events ---------------------------------------------------------------------------
    def _case_changed(self, event: Any) -> None:
        self.case = load_case(self.cases[event.new])
        self.set_case(self.case)
        self.on_change()

    def _changed(self, event: Any) -> None:
        if not self._quiet:
            self.on_change()

    def _law_changed(self, event: Any) -> None:
        """Enable the sliders of the chosen law's parameters, then rerun."""
        for k in self.knobs:
            if k.laws:
                applies = any(m in self.case.models for m in k.models)
                self.sliders[k.name].disabled = not applies or event.new not in k.laws
        self._changed(event)

    def panel(self, title: str = "parameters") -> pn.Column:
        """The widgets, for a page's side bar."""
        self._expert = [pn.pane.Markdown("exchange closure"), self.closure,
                        pn.pane.Markdown("geometry"), self.geometry, self.law,
                        self.scheme]
        self.set_present(self._present)
        return pn.Column(f"### {title}", self.case_select, *self.sliders.values(),
                         *self._expert, sizing_mode="stretch_width")

    def set_present(self, present: bool) -> None:
        """Presentation mode shows only the sliders of :data:`PRESENTED` (the case's
        values of the hidden ones still hold)."""
        self._present = present
        for name, s in self.sliders.items():
            s.visible = not present or name in PRESENTED
        for w in getattr(self, "_expert", []):
            w.visible = not present


def _keys_of_case(knob: Knob, case: Case) -> list[str]:
    """The knob's keys that ``case`` uses: [initial] and the sections of its models (a
    single-layer case on a slope must not get the two-layer model's flat bed)."""
    return [k for k in knob.keys
            if k.split(".")[0] in ("initial", "grid", "case", *case.models)]


def nice_step(target: float) -> float:
    """The number 1, 2 or 5 times a power of ten nearest to ``target`` (> 0) on a log
    scale: slider steps a class can read (2 m, 0.5 s)."""
    power = 10.0 ** math.floor(math.log10(target))
    return min((m * power for m in (1, 2, 5, 10)),
               key=lambda v: abs(math.log(v / target)))


def _range_around(s: Slider, knob: Knob, value: float, case: Case) -> None:
    """Put ``s`` on ``knob.around_case`` times ``value``; a domain length moves in whole
    cells of the case's dx and stays within :data:`MAX_CELLS` cells."""
    low, high = knob.around_case or (1.0, 1.0)
    step = nice_step(knob.step * value)
    end = high * value
    if knob.keys == ("grid.length",):
        dx = case.dx
        if not math.isclose(step / dx, round(step / dx), rel_tol=1e-9):
            step = dx * max(1, round(step / dx))
        end = min(end, MAX_CELLS * dx)
    # the case's own value is one of the slider's positions
    s.start = value - step * math.floor((value - low * value) / step + 1e-9)
    s.end = value + step * math.floor((end - value) / step + 1e-9)
    s.step = step


def _round_step(value: float, step: float) -> float:
    """``value`` rounded to a whole number of ``step`` (at least one step)."""
    return max(step, round(value / step) * step)
