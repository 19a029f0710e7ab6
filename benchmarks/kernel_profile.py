"""Where a workload's time goes, kernel by kernel: perf's samples on pdeflow's numba kernels.

numba's JIT code carries no symbols that ``perf`` can read. This script runs a workload
in a child process under ``perf record``, with sampling off; the child compiles the
workload's kernels afresh (into an empty numba cache of its own, so that every kernel's
LLVM module is in memory), writes perf's map of JIT code, ``/tmp/perf-<pid>.map``, with
the address range of every compiled function (:func:`write_perf_map`; removed after the
report), turns sampling on (the compilation is not sampled) and runs the workload
``repeats`` times. The report lists each function's share of the samples that fell in
compiled kernels, and the kernels' share of all samples (the rest: Python around the
runs, the solver's set-up of each run, the interpreter).

LLVM inlines small callees into their callers, so a function's share includes those it
inlined; a helper that appears on its own was called. Each caller links its own copy of
a callee: the copies' samples are summed under one name.

    python benchmarks/kernel_profile.py                        # the two-layer sweep
    python benchmarks/kernel_profile.py --model single_layer   # the one-layer sweep
    python benchmarks/kernel_profile.py --workload 5.1 --repeats 200

Workloads (those of ``benchmarks/layer_cost.py``): ``sweep``, the 5.2-like collapses of
the benchmark sweep to rest (``suite.sweep_case``); ``5.1``, the dam break at dx =
0.0125 m to t = 0.4 s, hll/first-order. Needs Linux ``perf`` (``perf record`` must be
allowed: ``kernel.perf_event_paranoid`` <= 2); cpu-clock samples, so it works in a
virtual machine without hardware counters.
"""

from __future__ import annotations

import argparse
import collections
import os
import re
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

CHILD = "PDEFLOW_KERNEL_PROFILE_CHILD"
"""set in the profiled child process"""
MAX_SIZE = 1 << 20
"""largest address range [bytes] given to one function in the map"""
_REPORT_LINE = re.compile(r"^\s*([\d.]+)%\s+\[\.\]\s+(\S+)")


def readable(mangled: str) -> str:
    """A numba function's symbol without the mangling: ``_ZN7pdeflow6models9two_layer
    8exchange18friction_two_layerB3v53...`` ->
    ``pdeflow.models.two_layer.exchange.friction_two_layer``
    (a ``cpython.`` or ``cfunc.`` prefix of a wrapper is kept; other names unchanged)."""
    prefix, _, rest = mangled.rpartition("_ZN")
    if not rest or not rest[0].isdigit():
        return mangled
    parts = []
    while rest and rest[0].isdigit():
        digits = re.match(r"\d+", rest).group()
        n = int(digits)
        parts.append(rest[len(digits):len(digits) + n])
        rest = rest[len(digits) + n:]
    name = ".".join(parts).replace("_3clocals_3e", "<locals>")
    return prefix + name


def compiled_functions(dispatchers: Iterable[Any]) -> list[tuple[int, str]]:
    """(address, symbol) of every function defined in the compiled code of
    ``dispatchers`` (numba dispatchers compiled in this process: a library loaded from
    the disk cache has no LLVM module to list and is left out), sorted by address."""
    found: dict[int, str] = {}
    seen: set[int] = set()
    for dispatcher in dispatchers:
        for cres in getattr(dispatcher, "overloads", {}).values():
            library = cres.library
            module = getattr(library, "_final_module", None)
            if id(library) in seen or module is None:
                continue
            seen.add(id(library))
            for function in module.functions:
                if function.is_declaration:
                    continue
                address = library.get_pointer_to_function(function.name)
                if address:
                    found[address] = function.name
    return sorted(found.items())


def write_perf_map(functions: list[tuple[int, str]], path: Path) -> int:
    """Write perf's JIT map (``START SIZE NAME`` in hex, one function a line) of
    ``functions`` (:func:`compiled_functions`): each function's range ends where the
    next one starts (at most :data:`MAX_SIZE`). Returns the number of lines."""
    lines = []
    for k, (address, name) in enumerate(functions):
        end = functions[k + 1][0] if k + 1 < len(functions) else address + MAX_SIZE
        lines.append(f"{address:x} {min(end - address, MAX_SIZE):x} {readable(name)}\n")
    path.write_text("".join(lines))
    return len(lines)


def kernel_shares(report: str, kernels: set[str]) -> tuple[dict[str, float], float]:
    """({kernel: % of the kernels' samples}, % of all samples in kernels) from the text
    of ``perf report --no-children --sort symbol --stdio`` (``kernels``: the names of
    the map)."""
    shares: dict[str, float] = collections.defaultdict(float)
    for line in report.splitlines():
        m = _REPORT_LINE.match(line)
        if m and m.group(2) in kernels:
            shares[m.group(2)] += float(m.group(1))
    total = sum(shares.values())
    if total == 0.0:
        return {}, 0.0
    return ({k: 100.0 * v / total for k, v in sorted(shares.items(), key=lambda kv: -kv[1])},
            total)


def workload_runs(workload: str, model: str) -> list[Callable[[], Any]]:
    """The runs of ``workload`` ('sweep' or '5.1') for ``model``: those of
    ``layer_cost``'s benchmark (``suite.fv_stepper_run`` callables)."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import layer_cost

    return [run for variant, run in layer_cost._runs(workload) if variant == model]


def perf_map(pid: int) -> Path:
    """Where perf looks for the JIT map of process ``pid`` (fixed by perf)."""
    return Path("/tmp") / f"perf-{pid}.map"


def child(workload: str, model: str, repeats: int, map_dir: Path) -> None:
    """The profiled process: compile, write the map (its pid and the mapped names in
    ``map_dir``), run ``repeats`` times."""
    from pdeflow.numerics.compiled import kernels

    runs = workload_runs(workload, model)
    for run in runs:
        run()  # compiles (the cache is empty)
    functions = compiled_functions(kernels())
    n = write_perf_map(functions, perf_map(os.getpid()))
    (map_dir / "pid.txt").write_text(str(os.getpid()))
    (map_dir / "names.txt").write_text("\n".join(sorted({readable(f) for _, f in functions})))
    print(f"kernel profile: {n} compiled functions mapped", file=sys.stderr)
    _enable_sampling(map_dir)
    for _ in range(repeats):
        for run in runs:
            run()


def _enable_sampling(tmp: Path) -> None:
    """Tell the ``perf record`` this process runs under (started with sampling off) to
    start sampling now, through its control fifo, and wait for its answer."""
    with open(tmp / "ctl", "w") as ctl:
        ctl.write("enable\n")
    with open(tmp / "ack") as ack:
        ack.readline()


def profile(workload: str, model: str, repeats: int, frequency: int) -> str:
    """Run the child under ``perf record``; the table of its kernels' shares."""
    perf = shutil.which("perf")
    if perf is None:
        raise SystemExit("kernel_profile: needs Linux perf (not found on PATH)")
    with tempfile.TemporaryDirectory(prefix="pdeflow-kernel-profile-") as tmp:
        data = Path(tmp) / "perf.data"
        env = {**os.environ, CHILD: tmp, "NUMBA_CACHE_DIR": str(Path(tmp) / "numba")}
        env.pop("NUMBA_DISABLE_JIT", None)
        for fifo in ("ctl", "ack"):
            os.mkfifo(Path(tmp) / fifo)
        # sampling starts disabled (-D -1): the child enables it once compiled
        subprocess.run([perf, "record", "-q", "-F", str(frequency), "-o", str(data), "-D",
                        "-1", f"--control=fifo:{tmp}/ctl,{tmp}/ack", "--",
                        sys.executable, __file__, "--workload", workload, "--model", model,
                        "--repeats", str(repeats)], env=env, check=True)
        pid = int((Path(tmp) / "pid.txt").read_text())
        try:
            report = subprocess.run([perf, "report", "-i", str(data), "--no-children",
                                     "--sort", "symbol", "--stdio"], capture_output=True,
                                    text=True, check=True).stdout
        finally:
            perf_map(pid).unlink(missing_ok=True)
        names = set((Path(tmp) / "names.txt").read_text().split("\n"))
    shares, total = kernel_shares(report, names)
    rows = [f"{model}, {workload} x {repeats}: {total:.1f} % of all samples in compiled "
            "kernels; their shares:"]
    rows += [f"{share:6.1f} %  {name}" for name, share in shares.items() if share >= 0.1]
    return "\n".join(rows)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--workload", choices=("sweep", "5.1"), default="sweep")
    ap.add_argument("--model", choices=("single_layer", "two_layer"), default="two_layer")
    ap.add_argument("--repeats", type=int, default=40,
                    help="runs of the workload profiled (default 40), >= 1")
    ap.add_argument("--frequency", type=int, default=2000,
                    help="samples per second (default 2000), 1-20000")
    args = ap.parse_args()
    if not args.repeats >= 1:
        ap.error(f"--repeats must be >= 1, got {args.repeats}")
    if not 1 <= args.frequency <= 20000:
        ap.error(f"--frequency must lie in [1, 20000], got {args.frequency}")
    if os.environ.get(CHILD):
        child(args.workload, args.model, args.repeats, Path(os.environ[CHILD]))
        return
    print(profile(args.workload, args.model, args.repeats, args.frequency))


if __name__ == "__main__":
    main()
