"""The teaching notebooks in docs/ execute from top to bottom (so they never rot).

Each notebook checks its own results with ``assert`` statements; a failing cell fails
the test. Needs the ``test`` extra (nbclient, nbformat, ipykernel, ipywidgets). When those
are missing or a Jupyter kernel cannot start here, the notebook tests are skipped on a
developer's machine but fail in CI (``PDEFLOW_CI=1``, set by .ci/run, or ``CI=true``):
there a missing kernel means the installation is broken and the notebooks went untested.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from .helpers import skip_or_fail_in_ci

try:
    import ipykernel  # noqa: F401  (the kernel the notebooks run in)
    import nbclient
    import nbformat
except ImportError as err:  # reported by the kernel_available fixture
    MISSING: ImportError | None = err
else:
    MISSING = None

DOCS = Path(__file__).parents[1] / "docs"
NOTEBOOKS = sorted(DOCS.glob("*.ipynb"))
#: the limit [s] of one cell: generous on purpose, it only stops a cell that hangs. A
#: notebook runs in seconds once the numba kernels are cached, but a first run compiles
#: them (minutes on a loaded machine); how fast the notebooks run is not a unit test's
#: business
CELL_TIMEOUT_S = 900


def _kernel_env() -> dict[str, str]:
    """The test's environment without a forced matplotlib backend (e.g. Agg), so that
    the kernel uses its inline backend as in a real notebook, and with the notebooks'
    sliders off: a cell that displays ipywidgets sometimes blocks nbclient until its
    timeout (jupyter/nbclient#312); the notebooks then call the same functions once
    with their default values."""
    env = dict(os.environ)
    env.pop("MPLBACKEND", None)
    env["PDEFLOW_NO_WIDGETS"] = "1"
    return env


@pytest.fixture(scope="module")
def kernel_available() -> None:
    if MISSING is not None:
        skip_or_fail_in_ci(f"the notebooks cannot run: {MISSING} (nbformat, nbclient and "
                           "ipykernel come with the test extra)")
    from jupyter_client.manager import start_new_kernel

    try:
        km, kc = start_new_kernel(kernel_name="python3", startup_timeout=60,
                                  env=_kernel_env())
    except Exception as err:  # no kernelspec, no zmq, sandbox without sockets, ...
        error = err
    else:
        kc.stop_channels()
        km.shutdown_kernel(now=True)
        return
    skip_or_fail_in_ci(f"no Jupyter kernel can start here: {error!r}")


def test_there_are_teaching_notebooks():
    names = {p.stem for p in NOTEBOOKS}
    assert {"anatomy_two_layer_dam_break", "hyperbolicity_and_fextra",
            "single_vs_two_layers_runout"} <= names


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_notebook_executes(path, kernel_available):
    nb = nbformat.read(path, as_version=4)
    code = "\n".join(c.source for c in nb.cells if c.cell_type == "code")
    assert "assert " in code, "a notebook must check its results"
    assert all(not c.get("outputs") for c in nb.cells if c.cell_type == "code"), \
        "store notebooks without outputs (they are produced when run)"
    client = nbclient.NotebookClient(nb, timeout=CELL_TIMEOUT_S, kernel_name="python3",
                                     resources={"metadata": {"path": str(DOCS)}})
    client.execute(env=_kernel_env())  # raises CellExecutionError on a failing cell
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    images = [o for o in outputs if "image/png" in o.get("data", {})]
    assert images, "the notebook should show figures"


@pytest.mark.parametrize("env, outcome", [
    ({}, pytest.skip.Exception),
    ({"PDEFLOW_CI": "1"}, pytest.fail.Exception),
    ({"CI": "true"}, pytest.fail.Exception),
])
def test_a_missing_kernel_skips_here_and_fails_in_ci(monkeypatch, env, outcome):
    monkeypatch.delenv("PDEFLOW_CI", raising=False)
    monkeypatch.delenv("CI", raising=False)
    for key, value in env.items():
        monkeypatch.setenv(key, value)
    with pytest.raises(outcome, match="no Jupyter kernel"):
        skip_or_fail_in_ci("no Jupyter kernel can start here")
