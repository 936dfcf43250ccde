"""``python -m benchmarks.general_suite [--problems N] [--out DIR]``.

Solves the first ``N`` problems of the suite (all 543 by default) with every solver
that applies, judges each run (:mod:`benchmarks.general_suite.yardstick`), prints the
report and writes it to ``DIR/report.md`` with one CSV line per run in
``DIR/runs.csv``. ``DIR`` defaults to ``benchmarks/out/general_suite`` (git-ignored).
"""

from __future__ import annotations

import argparse
import contextlib
import csv
import dataclasses
import os
import sys
from collections.abc import Iterator
from pathlib import Path

from benchmarks.general_suite.families import FEASIBLE, SuiteProblem, suite
from benchmarks.general_suite.runs import SOLVERS, applies, run
from benchmarks.general_suite.table import Record, report
from benchmarks.general_suite.yardstick import (
    objective_error,
    point_failures,
    success,
    verified,
)
from reference import Reference, clarabel_solve

DEFAULT_OUT = Path(__file__).resolve().parents[1] / "out" / "general_suite"


def reference_of(item: SuiteProblem) -> Reference:
    """Clarabel at 1e-10 for a feasible problem; none for an infeasible one."""
    if item.expected != FEASIBLE:
        return Reference(item.expected, None, None)
    return clarabel_solve(*item.problem.args(), tol=1e-10)


def judge(item: SuiteProblem) -> tuple[list[Record], bool]:
    """Every applicable solver's record for ``item``, and whether its reference failed."""
    reference = reference_of(item)
    p = item.problem
    records = []
    for solver in SOLVERS:
        if not applies(solver, p):
            continue
        outcome = run(solver, p)
        feasible = item.expected == FEASIBLE
        records.append(Record(
            index=item.index, family=item.family, member=item.member,
            expected=item.expected, n=p.n, m=p.b.shape[0], cones=len(p.cones),
            solver=solver, status=outcome.status, claim=outcome.claim, time=outcome.time,
            success=success(item, outcome, reference),
            objective_error=objective_error(item, outcome, reference),
            failed_checks=";".join(point_failures(item, outcome)) if feasible else "",
            verified=verified(item, outcome) if solver == "fccqp" else None,
        ))
    return records, item.expected == FEASIBLE and reference.obj is None


@contextlib.contextmanager
def quiet_stdout() -> Iterator[None]:
    """Send file descriptor 1 to /dev/null: OSQP's polish prints there from C even when
    not verbose, which would interleave with the report."""
    sys.stdout.flush()
    saved = os.dup(1)
    with open(os.devnull, "w") as devnull:
        os.dup2(devnull.fileno(), 1)
        try:
            yield
        finally:
            os.dup2(saved, 1)
            os.close(saved)


def write_csv(path: Path, records: list[Record]) -> None:
    fields = [f.name for f in dataclasses.fields(Record)]
    with path.open("w", newline="") as stream:
        writer = csv.DictWriter(stream, fieldnames=fields)
        writer.writeheader()
        writer.writerows(dataclasses.asdict(r) for r in records)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.general_suite",
                                     description=__doc__.split("\n\n")[1])
    parser.add_argument("--problems", type=int, default=None,
                        help="solve the first N problems of the suite (default: all)")
    parser.add_argument("--out", type=Path, default=DEFAULT_OUT,
                        help=f"output folder (default: {DEFAULT_OUT})")
    args = parser.parse_args(argv)
    items = suite(args.problems)
    records, missing = [], 0
    with quiet_stdout():
        for done, item in enumerate(items, 1):
            item_records, no_reference = judge(item)
            records += item_records
            missing += no_reference
            if done % 50 == 0 or done == len(items):
                print(f"{done}/{len(items)} problems", file=sys.stderr, flush=True)
    text = report(records, missing)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "report.md").write_text(text)
    write_csv(args.out / "runs.csv", records)
    print(text)


if __name__ == "__main__":
    main()
