"""Numerical variants: one type for every choice of discretisation and integrator.

A :class:`Variant` names how a case is solved, never what is solved: the interface flux,
the reconstruction and its limiter, the splitting, the hyperbolicity treatment (the
two-layer model's ``hyperbolicity`` parameter) and the integrator. Its name is the one the
docs use::

    FLUX/RECONSTRUCTION[/LIMITER][+SPLITTING][@HYPERBOLICITY]   the fv-split scheme
    mol-SOLVER[:FLUX/RECONSTRUCTION[/LIMITER]][@HYPERBOLICITY]     method of lines

e.g. ``hll/first-order`` (the paper's scheme), ``hll/muscl/mc+strang``,
``hll/first-order@bound``, ``mol-rk`` (py-pde's classical RK4 with a fixed step on the
method-of-lines rate of hll/first-order), ``mol-euler:rusanov/first-order``; ``SOLVER`` is
``rk`` or ``euler`` or the name of any py-pde solver (``mol-scipy``). The limiter
defaults to minmod, the splitting to Lie, the hyperbolicity treatment to the paper's
exact test; defaults are left out of :attr:`Variant.name`, so a name printed is a name
parsed.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any

from .numerics.scheme import (
    FLUXES,
    LIMITERS,
    MAX_CFL,
    RECONSTRUCTIONS,
    SPLITTINGS,
    Scheme,
    SchemeError,
    check_choice,
)

__all__ = ["FLUXES", "HYPERBOLICITY", "LIMITERS", "MAX_CFL", "RECONSTRUCTIONS",
           "SPLITTINGS", "Scheme", "Variant", "VariantError", "variant_of"]

HYPERBOLICITY: tuple[str, ...] = ("exact", "bound", "none")
MOL_SOLVERS: dict[str, str] = {"mol-rk": "runge-kutta", "mol-euler": "euler"}
"""short method-of-lines names -> py-pde solver names; any other py-pde solver is
``mol-<its name>``"""

_SCHEME = r"(?P<flux>[a-z]+)/(?P<rec>[a-z-]+)(?:/(?P<lim>[a-z]+))?"
_FV_RE = re.compile(rf"^{_SCHEME}(?:\+(?P<split>[a-z]+))?(?:@(?P<hyp>[a-z]+))?$")
_MOL_RE = re.compile(rf"^(?P<mol>mol-[a-z-]+)(?::{_SCHEME})?(?:@(?P<hyp>[a-z]+))?$")

GRAMMAR = ("FLUX/RECONSTRUCTION[/LIMITER][+SPLITTING][@HYPERBOLICITY] or "
           "mol-SOLVER[:FLUX/RECONSTRUCTION[/LIMITER]][@HYPERBOLICITY]")


UNFIT_SOLVERS: dict[str, str] = {
    "milstein": "a stochastic solver, and the models have no noise",
    "explicit_mpi": "it runs only under MPI (mpi4py, mpiexec) on a grid split across "
                    "processes",
    "implicit": "its fixed-point iteration does not converge on the friction sources "
                "(a ConvergenceError on test 5.1)",
    "crank-nicolson": "its fixed-point iteration does not converge on the friction "
                      "sources (a ConvergenceError on test 5.1)",
}
"""py-pde's registered solvers that cannot run a case, and why: they are not offered"""


def solver_names() -> list[str]:
    """Solvers a variant can name: fv-split first, then py-pde's registered solvers
    that can run a case (each integrates the method-of-lines rate; not
    :data:`UNFIT_SOLVERS`)."""
    import pde.solvers

    from . import solvers  # noqa: F401 - registers fv-split

    names = [n for n in pde.solvers.registered_solvers()
             if not n.endswith("Solver") and n not in UNFIT_SOLVERS]
    return sorted(names, key=lambda n: (n != "fv-split", n))


class VariantError(SchemeError):
    """A variant name or field that is not one of the allowed choices."""


def _choice(what: str, value: str, allowed: tuple[str, ...], name: str | None) -> None:
    where = f"variant {name!r}: " if name else ""
    try:
        check_choice(what, value, allowed, where)
    except SchemeError as err:
        why = (f" (py-pde's {value!r} cannot run a case: {UNFIT_SOLVERS[value]})"
               if what.endswith("solver") and value in UNFIT_SOLVERS else "")
        raise VariantError(f"{err}{why}") from None


def _of_scheme(field: str, what: str) -> Any:
    """A read-only property: the scheme's ``field``."""
    return property(lambda self: getattr(self.scheme, field), doc=f"The scheme's {what}.")


def _scheme(name: str | None, *fields: str) -> Scheme:
    """``Scheme(*fields)``, or VariantError naming the variant ``name``."""
    try:
        return Scheme(*fields)
    except SchemeError as err:
        where = f"variant {name!r}: " if name else ""
        raise VariantError(f"{where}{err}") from None


@dataclass(frozen=True)
class Variant:
    """How a case is solved: a :class:`~pdeflow.numerics.scheme.Scheme` (flux,
    reconstruction, limiter, splitting), the hyperbolicity treatment and the integrator.

    ``solver`` is ``"fv-split"`` (the paper's split scheme, a CFL time step) or a
    py-pde solver name run with a fixed step on the method-of-lines rate (see
    :data:`MOL_SOLVERS`); the scheme's splitting applies to fv-split only. ``flux``,
    ``reconstruction``, ``limiter`` and ``splitting`` read the scheme.
    """

    scheme: Scheme = Scheme()
    hyperbolicity: str = "exact"
    solver: str = "fv-split"

    def __post_init__(self) -> None:
        if not isinstance(self.scheme, Scheme):
            raise VariantError(f"scheme must be a Scheme, got {self.scheme!r}")
        name = self.name
        _choice("hyperbolicity", self.hyperbolicity, HYPERBOLICITY, name)
        _choice("solver", self.solver, tuple(solver_names()), name)
        if self.solver != "fv-split" and self.splitting != "lie":
            raise VariantError(f"variant {name!r}: splitting applies to the fv-split "
                               "solver only (the method of lines does not split)")

    flux = _of_scheme("flux", "interface flux")
    reconstruction = _of_scheme("reconstruction", "reconstruction")
    limiter = _of_scheme("limiter", "slope limiter (of 'muscl')")
    splitting = _of_scheme("splitting", "splitting (fv-split only)")

    # --- names ---------------------------------------------------------------------------
    @classmethod
    def parse(cls, name: str) -> Variant:
        """The variant of a name (grammar in the module docstring); VariantError names
        the part that is wrong and the allowed choices."""
        text = str(name).strip()
        m = _FV_RE.match(text) or _MOL_RE.match(text)
        if not m:
            raise VariantError(f"variant {text!r} is not {GRAMMAR} (fluxes "
                               f"{list(FLUXES)}, reconstructions {list(RECONSTRUCTIONS)},"
                               f" limiters {list(LIMITERS)}, splittings "
                               f"{list(SPLITTINGS)}, hyperbolicity {list(HYPERBOLICITY)})")
        parts = m.groupdict()
        if parts.get("lim") and parts.get("rec") != "muscl":
            raise VariantError(f"variant {text!r}: a limiter needs the muscl "
                               "reconstruction")
        kwargs: dict[str, Any] = {"hyperbolicity": parts.get("hyp") or "exact"}
        if parts.get("mol"):
            solver = MOL_SOLVERS.get(parts["mol"], parts["mol"][4:])
            if solver not in solver_names() or solver == "fv-split":
                known = list(dict.fromkeys(
                    [*MOL_SOLVERS, *(f"mol-{n}" for n in solver_names()[1:])]))
                why = (f" (py-pde's {solver!r} cannot run a case: "
                       f"{UNFIT_SOLVERS[solver]})" if solver in UNFIT_SOLVERS else "")
                raise VariantError(f"variant {text!r}: the method of lines must be one "
                                   f"of {known}, got {parts['mol']!r}{why}")
            kwargs["solver"] = solver
        splitting = parts.get("split") or "lie"
        scheme = (parts["flux"], parts["rec"], parts.get("lim") or "minmod") \
            if parts.get("flux") else ("hll", "first-order", "minmod")
        return cls(_scheme(text, *scheme, splitting), **kwargs)

    @property
    def name(self) -> str:
        """Canonical name (defaults left out); ``Variant.parse(v.name) == v``."""
        hyp = "" if self.hyperbolicity == "exact" else f"@{self.hyperbolicity}"
        if self.solver == "fv-split":
            return f"{self.scheme.name}{hyp}"
        mol = {v: k for k, v in MOL_SOLVERS.items()}.get(self.solver,
                                                         f"mol-{self.solver}")
        if self.scheme.spatial == "hll/first-order":
            return f"{mol}{hyp}"
        return f"{mol}:{self.scheme.spatial}{hyp}"

    def __str__(self) -> str:
        return self.name

    @property
    def description(self) -> str:
        """One line in words, for tables and legends."""
        rec = ("first order" if self.reconstruction == "first-order"
               else f"MUSCL ({self.limiter})")
        if self.solver == "fv-split":
            how = f"fv-split, {self.splitting.capitalize()} splitting"
            if self.reconstruction == "muscl":
                how += ", SSP-RK2 advection"
        else:
            how = f"py-pde {self.solver}, fixed dt, method of lines"
        hyp = {"exact": "exact hyperbolicity test", "bound": "hyperbolicity restored "
               "below F_L only", "none": "no hyperbolicity correction"}[self.hyperbolicity]
        if self.is_mol:  # the hook runs the source stage with dt = 0: nothing to restore
            hyp = "no hyperbolicity correction (sources in the rate)"
        return f"{self.flux.upper()} flux, {rec}; {how}; {hyp}"

    @property
    def is_mol(self) -> bool:
        """True for a py-pde solver on the method-of-lines rate."""
        return self.solver != "fv-split"

    def numerics(self) -> dict[str, Any]:
        """The case file's ``[numerics]`` entries that select this variant."""
        out: dict[str, Any] = {"solver": self.solver, "flux": self.flux,
                               "reconstruction": self.reconstruction,
                               "limiter": self.limiter}
        if self.solver == "fv-split":
            out["splitting"] = self.splitting
        return out


def variant_of(numerics: dict[str, Any], hyperbolicity: str = "exact") -> Variant:
    """The variant that a case file's ``[numerics]`` table and two-layer
    ``hyperbolicity`` select; VariantError names the case file's key that is wrong."""
    fields = {"solver": numerics.get("solver", "fv-split"),
              "flux": numerics.get("flux", "hll"),
              "reconstruction": numerics.get("reconstruction", "first-order"),
              "limiter": numerics.get("limiter", "minmod"),
              "splitting": numerics.get("splitting", "lie")}
    allowed = {"solver": tuple(solver_names()), "flux": FLUXES,
               "reconstruction": RECONSTRUCTIONS, "limiter": LIMITERS,
               "splitting": SPLITTINGS}
    for key, value in fields.items():  # errors name the case file's key
        _choice(f"numerics.{key}", value, allowed[key], None)
    if fields["solver"] != "fv-split":
        fields["splitting"] = "lie"  # the method of lines does not split
    _choice("two_layer.hyperbolicity", hyperbolicity, HYPERBOLICITY, None)
    scheme = _scheme(None, *(fields[k] for k in ("flux", "reconstruction", "limiter",
                                                  "splitting")))
    return Variant(scheme, hyperbolicity, fields["solver"])
