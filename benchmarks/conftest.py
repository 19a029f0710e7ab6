"""pytest configuration of the benchmark suite (``python -m pytest benchmarks``).

Not collected by the default test run (``testpaths = ["tests"]``). Needs
pytest-benchmark (``pip install ".[bench]"``); PyClaw tests skip without clawpack.
"""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
