"""A generated suite of general QPs, solved by fccqp and its peers at eps 1e-6.

``python -m benchmarks.general_suite [--problems N] [--out DIR]`` (see
:mod:`benchmarks.general_suite.__main__`) solves the suite of
:mod:`benchmarks.general_suite.families` with fccqp, Clarabel, OSQP and PIQP
(:mod:`~benchmarks.general_suite.runs`), judges every returned point by the same
yardstick (:mod:`~benchmarks.general_suite.yardstick`) and writes a Markdown table
(:mod:`~benchmarks.general_suite.table`).

The checks come from the test suite's ``tests/verify.py`` and the references from
``tests/reference.py``; like pytest (``pythonpath = ["tests"]`` in pyproject.toml), this
package puts ``tests/`` on ``sys.path`` so that both import as ``verify`` and
``reference``.
"""

import sys
from pathlib import Path

_TESTS = str(Path(__file__).resolve().parents[2] / "tests")
if _TESTS not in sys.path:
    sys.path.append(_TESTS)
