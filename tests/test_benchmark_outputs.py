"""Where the benchmark writes: the default output and cache folders are ignored by git,
the committed reports are not; the qpbenchmark export has qpbenchmark's layout; the
deadline and work-precision metrics count failures as failures."""

from __future__ import annotations

import ast
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from benchmarks.cache import DEFAULT_CACHE, cache_path
from benchmarks.cli import DEFAULT_OUT
from benchmarks.export import SCRIPT_NAME, write_qpbenchmark
from benchmarks.metrics import deadline_share, penalized_times, percentile, solved_torque_errors
from benchmarks.testsets import generate_test_set

ROOT = Path(__file__).resolve().parent.parent


def _ignored(path: Path) -> bool:
    if shutil.which("git") is None or not (ROOT / ".git").exists():
        pytest.skip("not a git checkout")
    result = subprocess.run(["git", "check-ignore", "-q", str(path)], cwd=ROOT)
    return result.returncode == 0


def test_default_output_and_cache_are_ignored_by_git():
    assert _ignored(DEFAULT_OUT / "quick" / "report.md")
    assert _ignored(cache_path(DEFAULT_CACHE, "solo12", "mix", 60, 0, 15, 0.002))


def test_committed_reports_are_not_ignored():
    assert not _ignored(ROOT / "benchmarks" / "results" / "quick" / "report.md")


def test_qpbenchmark_export_layout(tmp_path):
    ts = generate_test_set("solo12", "mix", 2, seed=4, seq_len=2)
    script = write_qpbenchmark([ts], tmp_path, "python -m benchmarks export --qpbenchmark X")
    assert script.name == SCRIPT_NAME and (tmp_path / "results").is_dir()
    files = sorted((tmp_path / "data").glob("*.npz"))
    assert [f.stem for f in files] == ["solo12_mix_seed4_0000", "solo12_mix_seed4_0001"]
    with np.load(files[0], allow_pickle=False) as z:
        assert set(z.files) == {"P", "q", "G", "h", "A", "b", "lb", "ub"}
        qp = ts.qps[0]
        assert z["G"].shape == (5 * qp.n_contacts, qp.n)  # 4 facets + unilateral row
        np.testing.assert_array_equal(z["A"], qp.A)
    classes = [n.name for n in ast.walk(ast.parse(script.read_text()))
               if isinstance(n, ast.ClassDef)]
    assert classes == ["WbcPyramidQpbenchmark"]  # qpbenchmark: file name in PascalCase


def _row(time, reported=True, feasible=True, err=0.01):
    return {"time": time, "reported": reported, "feasible": feasible, "torque_error_rel": err}


def test_deadline_share_counts_only_timely_solved_feasible_accurate_answers():
    rows = [_row(1e-4), _row(3e-4), _row(1e-4, reported=False), _row(1e-4, feasible=False),
            _row(1e-4, err=0.2)]
    assert deadline_share(rows, 250e-6) == pytest.approx(1 / 5)
    assert deadline_share(rows, 500e-6) == pytest.approx(2 / 5)


def test_unsolved_qps_count_as_infinite_torque_error():
    errors = solved_torque_errors([_row(1e-4, err=0.01), _row(1e-4, reported=False, err=0.0)])
    assert errors[0] == 0.01 and np.isinf(errors[1])


def test_unsolved_qps_count_as_the_controller_period_in_time():
    times = penalized_times([_row(1e-4), _row(1e-4, reported=False),
                             _row(3e-3, reported=False)], 2e-3)
    np.testing.assert_array_equal(times, [1e-4, 2e-3, 3e-3])


def test_percentiles_are_nearest_ranks():
    """The value of an actual QP: of 60, p95 is the 57th smallest, p99 the largest; an
    infinite value (a failure) counts only when it is that rank."""
    values = np.arange(1.0, 61.0)
    assert percentile(values, 95) == 57 and percentile(values, 99) == 60
    assert percentile(values, 50) == 30 and percentile(values, 100) == 60
    failed = np.r_[np.ones(57), np.inf, np.inf, np.inf]
    assert percentile(failed, 95) == 1 and np.isinf(percentile(failed, 96))
