"""Shared configuration of the tests: they run headless."""

import matplotlib

# figures are drawn with Agg (no window, no display needed), whatever MPLBACKEND says;
# the notebooks' kernel, a separate process, keeps its inline backend (test_notebooks)
matplotlib.use("Agg")
