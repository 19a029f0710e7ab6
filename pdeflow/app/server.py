"""Serve the teaching app in the browser: four pages (dam break, run-out law,
hyperbolicity, hillside) where every slider or run button reruns pdeflow in the server.

The page opens in the default browser (unless --no-browser) at http://HOST:PORT/;
?page=run-out, ?page=hyperbolicity or ?page=hillside opens another page first; --present (or
?present=1) opens in presentation mode, for a projector: larger fonts and lines, fewer
controls (a toggle in the header switches it). The first start on a
machine compiles the numerical kernels (the page says so, with the elapsed time); later
starts load them in under a second. Ctrl-C stops the server.

With --host 0.0.0.0 (or the machine's address) students on the same network can open
the page at http://<teacher's machine>:PORT/; every open page reruns cases on this
machine. Needs panel: pip install ".[app]"; the case files come from ./cases, the
repository's cases/ or --cases DIR.

examples:
  pdeflow app                                  # http://127.0.0.1:5006/ in the browser
  pdeflow app --port 8000 --no-browser
  pdeflow app --host 0.0.0.0                   # a class on the local network
  pdeflow app --present                        # on a projector
"""

from __future__ import annotations

import argparse
import ipaddress
import socket
import sys
from pathlib import Path
from typing import Any

DEFAULT_PORT = 5006


def add_arguments(ap: argparse.ArgumentParser) -> None:
    """The options of ``pdeflow app``."""
    ap.add_argument("--port", type=int, default=DEFAULT_PORT,
                    help=f"TCP port to serve on, 0-65535 (default {DEFAULT_PORT}; 0 picks "
                    "a free one)")
    ap.add_argument("--host", default="127.0.0.1",
                    help="address to listen on (default 127.0.0.1: this machine only; "
                    "0.0.0.0: every network interface)")
    ap.add_argument("--no-browser", action="store_true",
                    help="do not open the page in a browser (print its address only)")
    ap.add_argument("--present", action="store_true",
                    help="open in presentation mode: larger fonts and lines, fewer "
                    "controls (also ?present=1 in the URL)")
    ap.add_argument("--cases", metavar="DIR",
                    help="directory of case files (default: ./cases, else the "
                    "repository's cases/)")


def _free_port(host: str) -> int:
    with socket.socket(socket.AF_INET6 if ":" in host else socket.AF_INET) as s:
        s.bind((host, 0))
        return int(s.getsockname()[1])


def _is_loopback(host: str) -> bool:
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def cmd_app(args: argparse.Namespace) -> int:
    """``pdeflow app``: check the options, then serve until Ctrl-C."""
    if not 0 <= args.port <= 65535:
        print(f"pdeflow: error: --port must lie in [0, 65535], got {args.port}",
              file=sys.stderr)
        return 2
    try:
        import panel  # noqa: F401
    except ImportError:
        print("pdeflow: error: pdeflow app needs panel: pip install \".[app]\"",
              file=sys.stderr)
        return 2
    from .controls import find_case_dir

    case_dir = find_case_dir(args.cases)  # CaseError: one line, exit 2 (pdeflow.cli)
    try:
        port = args.port or _free_port(args.host)
        server = make_server(case_dir, port, args.host, present=args.present)
    except OSError as err:  # address in use, unknown host, ...
        print(f"pdeflow: error: cannot serve on --host {args.host} --port {args.port}: "
              f"{err.strerror or err}", file=sys.stderr)
        return 2
    shown = socket.gethostname() if args.host in ("0.0.0.0", "::") else args.host
    print(f"pdeflow app: serving {case_dir} at http://{shown}:{port}/ "
          "(Ctrl-C stops it)", flush=True)
    if not _is_loopback(args.host):
        print("pdeflow app: every machine that reaches this address can use the app",
              flush=True)
    if not args.no_browser:
        server.io_loop.add_callback(server.show, "/")
    try:
        server.start()
        server.io_loop.start()
    except KeyboardInterrupt:
        pass
    finally:
        server.stop()
    return 0


def make_server(case_dir: Path, port: int, host: str, present: bool = False) -> Any:
    """A Bokeh server (not started) with the app at /, and the kernels loading
    (``present``: pages open in presentation mode)."""
    import panel as pn

    from .kernels import WARMUP
    from .layout import create_app

    origins = ([f"localhost:{port}", f"127.0.0.1:{port}"] if _is_loopback(host)
               else ["*"])

    def session() -> Any:  # Panel calls a function once per browser session
        return create_app(case_dir, present=present)

    server = pn.serve(session, port=port, address=host, websocket_origin=origins,
                      show=False, start=False, title="pdeflow", verbose=False)
    WARMUP.start()  # compile while the first browser connects
    return server
