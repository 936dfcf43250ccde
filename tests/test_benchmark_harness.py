"""End-to-end run of the benchmark harness, its metrics and its command-line errors."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest
from benchmarks.cli import main
from benchmarks.metrics import qp_metrics, shifted_geometric_mean
from benchmarks.solvers import VARIANTS, available_variants, make_adapter
from benchmarks.testsets import generate_test_set

N_QPS = 6


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A tiny run: solo12, 6 QPs in two sequences, one timing pass, every solver."""
    out = tmp_path_factory.mktemp("bench")
    cache = tmp_path_factory.mktemp("cache")
    argv = ["--robots", "solo12", "--n-qps", str(N_QPS), "--seq-len", "3", "--repeats", "1",
            "--out", str(out), "--cache", str(cache), "--no-progress"]
    main(argv)
    return out


def test_outputs_exist_and_are_not_empty(run: Path) -> None:
    names = ["report.md", "results.csv", "times_solo12.png", "torque_solo12.png",
             "work_precision_solo12.png", "time_distribution.png"]
    for name in names:
        assert (run / name).stat().st_size > 0, name


def test_csv_has_one_row_per_solver_and_qp(run: Path) -> None:
    with open(run / "results.csv") as fh:
        rows = list(csv.DictReader(fh))
    installed, _ = available_variants(list(VARIANTS))
    warm = [r for r in rows if r["view"] == "warm"]
    assert len(warm) == len(installed) * N_QPS
    assert {(r["solver"], int(r["qp"])) for r in warm} == {
        (s, i) for s in installed for i in range(N_QPS)
    }
    assert all(float(r["time"]) > 0 for r in rows)


def test_csv_holds_every_view(run: Path) -> None:
    """Every variant walks the warm view; the solvers at their defaults through their own
    APIs walk the cold and coarse views too (every 5th and 10th of two 3-tick sequences:
    their first QPs)."""
    from benchmarks.views import runs_every_view

    with open(run / "results.csv") as fh:
        rows = list(csv.DictReader(fh))
    installed, _ = available_variants(list(VARIANTS))
    every = [s for s in installed if runs_every_view(s)]
    for view, count in (("warm", N_QPS), ("cold", N_QPS), ("every 5th", 2), ("every 10th", 2)):
        mine = [r for r in rows if r["view"] == view]
        solvers = installed if view == "warm" else every
        assert len(mine) == len(solvers) * count, view
    assert {int(r["qp"]) for r in rows if r["view"] == "every 5th"} == {0, 3}


def test_report_names_every_solver_and_the_targets(run: Path) -> None:
    text = (run / "report.md").read_text()
    installed, _ = available_variants(list(VARIANTS))
    for name in installed:
        assert f"| {name} |" in text
    assert "## Targets" in text and ("MET" in text or "MISSED" in text)
    assert "fastest exact-cone peer" in text and "fastest pyramid peer" in text
    for view in ("| warm |", "| cold |", "| every 5th |", "| every 10th |"):
        assert view in text
    assert "fccqp-realtime cold median <= 1x daqp-pyr4's" in text
    assert "BLAS" in text and "load average" in text
    assert "cython" not in text  # a build dependency, absent from a run's environment
    assert "issue" not in text.lower()  # readers have not seen the issue tracker


def test_reference_against_itself_has_zero_errors() -> None:
    ts = generate_test_set("solo12", "mix", 3, seed=1, seq_len=3)
    for qp, x in zip(ts.qps, ts.x_ref, strict=True):
        m = qp_metrics(qp, x, x)
        assert m.objective_gap == 0 and m.torque_error == 0 and m.torque_error_rel == 0
        assert m.accurate and m.feasible


def test_solver_outcomes_match_the_reference_roughly() -> None:
    """Every installed exact-cone variant solves a QP close to the reference."""
    ts = generate_test_set("anymal_c", "mix", 1, seed=2, seq_len=1)
    qp, x_ref = ts.qps[0], ts.x_ref[0]
    for name in ("fccqp-default", "clarabel"):
        if available_variants([name])[0]:
            adapter = make_adapter(name)
            outcome = adapter.solve(adapter.prepare(qp))
            assert outcome.success and outcome.time > 0
            assert qp_metrics(qp, outcome.x, x_ref).accurate


def test_shifted_geometric_mean() -> None:
    assert shifted_geometric_mean(np.array([2.0, 2.0])) == pytest.approx(2.0)
    with pytest.raises(ValueError):
        shifted_geometric_mean(np.array([-1.0]))


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--robots", "atlas"], "unknown robot 'atlas'; known: solo12"),
        (["--solvers", "gurobi"], "unknown solver 'gurobi'; known: fccqp-realtime"),
        (["--repeats", "0"], "expected a positive integer, got '0'"),
        (["--repeats", "many"], "expected a positive integer, got 'many'"),
        (["--quick", "--full"], "not allowed with argument"),
    ],
)
def test_bad_arguments_exit_with_clear_messages(
    argv: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    assert message in capsys.readouterr().err


def test_no_sweep_keeps_only_default_settings(tmp_path: Path) -> None:
    argv = ["--robots", "solo12", "--n-qps", "2", "--seq-len", "2", "--repeats", "1",
            "--solvers", "fccqp-default", "fccqp-eps1e-3", "clarabel-loose", "--no-sweep",
            "--out", str(tmp_path / "out"), "--cache", str(tmp_path / "cache"), "--no-progress"]
    main(argv)
    with open(tmp_path / "out" / "results.csv") as fh:
        assert {r["solver"] for r in csv.DictReader(fh)} == {"fccqp-default"}


def _sized_set(sizes: list[int]):
    from types import SimpleNamespace

    from benchmarks.testsets import TestSet

    qps = [SimpleNamespace(P=np.zeros((n, n)), A=np.zeros((2, n))) for n in sizes]
    return TestSet("solo12", "mix", 0, 0.002, qps, [np.zeros(n) for n in sizes],
                   np.zeros(len(sizes), dtype=int))


def test_warm_up_reaches_every_problem_size() -> None:
    """The warm-up solves the first QPs and the first QP of each later size, in every set
    a variant walks, so that a solver's first call on a size (fccqp's workspace per
    structure) is not timed."""
    from benchmarks.harness import WARMUP_QPS, _warmup_indices

    main = _sized_set([8] * 10 + [6] * 4 + [8] * 3 + [4] * 2)
    assert _warmup_indices([main]) == [(0, i) for i in (*range(WARMUP_QPS), 10, 17)]
    coarse = _sized_set([8] * 3 + [5] * 2 + [4])
    assert _warmup_indices([main, coarse])[-1] == (1, 3)
