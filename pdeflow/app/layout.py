"""The app: the three pages as tabs, built once the numba kernels are loaded, under a
header with the presentation-mode toggle (:mod:`.look`)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import panel as pn

from .controls import find_case_dir, served
from .dam_break import DamBreakPage, SharedRun
from .hyperbolicity import HyperbolicityPage
from .kernels import WARMUP
from .runout import RunoutPage

PAGES = {"dam-break": "Dam break", "run-out": "Run-out law",
         "hyperbolicity": "Hyperbolicity"}
"""Page keys (the URL's ``?page=``) and tab titles, in the order of the tabs."""
POLL_MS = 500
"""How often the waiting page updates its elapsed time [ms]."""

HEADER = """<h2 style="margin:0.2em 0">pdeflow: dry granular avalanches, one layer and
two layers</h2><p style="margin:0">Move a slider: the case runs again in the server (a few
milliseconds for the paper's dam break) and every number shown is what <code>pdeflow
run</code> prints for the same case and overrides.</p>"""


def _url_argument(name: str) -> str | None:
    """The URL's ``?name=value`` of a served session, if any."""
    if not served():
        return None
    value = (pn.state.session_args or {}).get(name)
    return value[0].decode() if value else None


def _requested_present() -> bool | None:
    """``?present=1`` (or 0) in the URL of a served session; None if not given."""
    value = _url_argument("present")
    if value is None:
        return None
    return value.lower() not in ("0", "false", "no", "off", "")


def build_pages(case_dir: Path, page: str | None = None, present: bool = False,
                toggle: pn.widgets.Toggle | None = None) -> pn.Tabs:
    """The three pages of one session as tabs (``page`` selects the one shown first;
    ``present``: presentation mode, switched by ``toggle`` if given)."""
    shared = SharedRun()
    dam = DamBreakPage(case_dir, shared, present=present)
    runout = RunoutPage(case_dir, start=page == "run-out", present=present)
    hyper = HyperbolicityPage(shared, present=present)
    tabs = pn.Tabs((PAGES["dam-break"], dam.panel()), (PAGES["run-out"], runout.panel()),
                   (PAGES["hyperbolicity"], hyper.panel()),
                   dynamic=True, sizing_mode="stretch_width")
    if toggle is not None:
        def switch(event: Any) -> None:
            with pn.io.hold():
                for p in (dam, runout, hyper):
                    p.set_present(event.new)
                for p in (dam, runout):  # the side bar follows the mode
                    p.layout.show_sidebar(not event.new)

        toggle.param.watch(switch, "value")
    if page in PAGES:
        tabs.active = list(PAGES).index(page)
    run_out = list(PAGES).index("run-out")
    # the run-out set (about 20 runs) is computed when its page is first shown
    tabs.param.watch(lambda e: runout.start() if e.new == run_out else None, "active")
    return tabs


def create_app(case_dir: str | Path | None = None, page: str | None = None,
               present: bool = False) -> pn.Column:
    """The app as a Panel object: served by ``pdeflow app``, or shown in Jupyter.

    Args:
        case_dir: directory of case files (default: ./cases or the repository's).
        page: the page shown first: 'dam-break', 'run-out' or 'hyperbolicity'
            (served, the URL's ``?page=`` chooses it).
        present: open in presentation mode (larger fonts and lines, fewer controls;
            served, the URL's ``?present=1`` or ``?present=0`` overrides it).

    While the kernels compile (once per machine) a served page shows that, with the
    elapsed time, and builds its pages when they are ready; elsewhere (Jupyter, a
    script) this call prints the same and waits.
    """
    case_dir = find_case_dir(case_dir)
    page = page or _url_argument("page")
    url_present = _requested_present()
    present = present if url_present is None else url_present
    WARMUP.start()
    status = pn.pane.HTML(WARMUP.message(), css_classes=["pdeflow-kernels"],
                          sizing_mode="stretch_width")
    body = pn.Column(status, sizing_mode="stretch_width")
    toggle = pn.widgets.Toggle(name="presentation mode", value=present, width=180,
                               css_classes=["pdeflow-present"], align="center")
    header = pn.Row(pn.pane.HTML(HEADER, sizing_mode="stretch_width"), toggle,
                    sizing_mode="stretch_width")
    app = pn.Column(header, body, sizing_mode="stretch_width")

    def build() -> None:
        if WARMUP.error is not None:
            status.object = f"<b>{WARMUP.message()}</b>"
            return
        body.objects = [build_pages(case_dir, page, toggle.value, toggle)]

    if WARMUP.done:
        build()
    elif served():
        polling: list[Any] = []

        def poll() -> None:
            status.object = f"<b>{WARMUP.message()}</b>"
            if WARMUP.done and polling:
                build()
                polling.pop().stop()

        # poll once the browser has loaded the page: pages built before that, when the
        # warm-up ended within the first second, were sometimes never shown
        pn.state.onload(lambda: polling.append(
            pn.state.add_periodic_callback(poll, period=POLL_MS)))
    else:
        pn.extension()  # Jupyter: load Panel's JavaScript (harmless in a script)
        print(WARMUP.message(), flush=True)
        WARMUP.wait()
        build()
    return app
