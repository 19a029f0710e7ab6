"""The app: the four pages as tabs, built once the numba kernels are loaded, under a
header with the presentation-mode toggle (:mod:`.look`)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import panel as pn

from .controls import find_case_dir, served
from .dam_break import DamBreakPage, SharedRun
from .hillside import HillsidePage
from .hyperbolicity import HyperbolicityPage
from .kernels import WARMUP
from .runout import RunoutPage

PAGES = {"dam-break": "Dam break", "run-out": "Run-out law",
         "hyperbolicity": "Hyperbolicity", "hillside": "Hillside"}
"""Page keys (the URL's ``?page=``) and tab titles, in the order of the tabs."""
POLL_MS = 500
"""How often the waiting page updates its elapsed time [ms]."""

HEADER = """<h2 style="margin:0; font-size:1.3em">pdeflow: dry granular avalanches, one
layer and two layers</h2><p style="margin:0">Move a slider, or draw a release and press
run on the hillside: every number shown is what <code>pdeflow run</code> prints.</p>"""
"""Two lines on a projector's 1024 px: the figures start high enough to fit below."""


def _url_argument(name: str) -> str | None:
    """The URL's ``?name=value`` of a served session, if any."""
    if not served():
        return None
    value = (pn.state.session_args or {}).get(name)
    return value[0].decode() if value else None


def _styles_from_this_server() -> None:
    """Point the session's stylesheets at this server, before any is made.

    Panel's widgets name their stylesheets by CDN address and rewrite them to the
    server's own (``dist_url``) as they are made, or once the page is rendered; made
    before that, Panel's loading.css got the CDN address, and a browser later asked
    cdn.holoviz.org for it (seen after case changes; issue 38 saw it at the
    presentation toggle), which a machine offline cannot load. The address set here
    is the one Panel's page template gives the same document."""
    from panel.io.resources import LOCAL_DIST, use_cdn

    if not served() or use_cdn():
        return
    rel = pn.state.rel_path
    pn.state.curdoc._template_variables.setdefault(
        "dist_url", f"{rel}/{LOCAL_DIST}" if rel else LOCAL_DIST)


def _requested_present() -> bool | None:
    """``?present=1`` (or 0) in the URL of a served session; None if not given."""
    value = _url_argument("present")
    if value is None:
        return None
    return value.lower() not in ("0", "false", "no", "off", "")


class SessionPages:
    """The pages of one session, each built when its tab is first shown: the
    dam-break page at once (the hyperbolicity page shows its run), the others on
    demand, so the first picture does not wait for pages nobody looks at yet."""

    def __init__(self, case_dir: Path, page: str | None = None, present: bool = False):
        self.case_dir = case_dir
        self.first = page
        self.present = present
        self.shared = SharedRun()
        self.pages: dict[str, Any] = {}
        self.holders = {key: pn.Column(sizing_mode="stretch_width") for key in PAGES}

    def build(self, key: str) -> Any:
        """The page ``key``, built (in the current mode) and put in its tab if new."""
        if key not in self.pages:
            if key == "dam-break":
                page: Any = DamBreakPage(self.case_dir, self.shared, present=self.present)
            elif key == "hillside":
                page = HillsidePage(self.case_dir, present=self.present)
            elif key == "run-out":
                page = RunoutPage(self.case_dir, start=self.first == "run-out",
                                  present=self.present)
            else:
                page = HyperbolicityPage(self.shared, present=self.present)
            self.pages[key] = page
            self.holders[key].objects = [page.panel()]
            page.layout.set_present(self.present)
        return self.pages[key]

    def show(self, key: str) -> None:
        """The tab ``key`` opened: build its page; the run-out set starts computing."""
        page = self.build(key)
        if key == "run-out":
            page.start()  # the run-out set (about 20 runs): when first shown

    def set_present(self, present: bool) -> None:
        """Presentation mode on or off, for the pages built and those to come."""
        self.present = present
        with pn.io.hold():
            for key, p in self.pages.items():
                p.set_present(present)
                p.layout.set_present(present)
                if key != "hyperbolicity":  # the side bar follows the mode
                    p.layout.show_sidebar(not present)


def build_pages(case_dir: Path, page: str | None = None, present: bool = False,
                toggle: pn.widgets.Toggle | None = None,
                pages: SessionPages | None = None) -> pn.Tabs:
    """The pages of one session as tabs (``page`` selects the one shown first;
    ``present``: presentation mode, switched by ``toggle`` if given). Only the
    dam-break page and the one shown first are built now, the others when their tab
    is first opened (``pages``: the session's pages, default new ones)."""
    pages = pages or SessionPages(case_dir, page, present)
    pages.build("dam-break")
    keys = list(PAGES)
    tabs = pn.Tabs(*((PAGES[k], pages.holders[k]) for k in keys),
                   dynamic=True, sizing_mode="stretch_width")
    if toggle is not None:
        toggle.param.watch(lambda e: pages.set_present(e.new), "value")
    if page in PAGES:
        pages.show(page)
        tabs.active = keys.index(page)
    tabs.param.watch(lambda e: pages.show(keys[e.new]), "active")
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
    _styles_from_this_server()
    case_dir = find_case_dir(case_dir)
    page = page or _url_argument("page")
    url_present = _requested_present()
    present = present if url_present is None else url_present
    WARMUP.start()
    status = pn.pane.HTML(WARMUP.message(), css_classes=["pdeflow-kernels"],
                          sizing_mode="stretch_width")
    body = pn.Column(status, sizing_mode="stretch_width")
    toggle = pn.widgets.Toggle(name="presentation mode", value=present, width=180,
                               height=30, css_classes=["pdeflow-present"], align="center")
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
