"""The suite's records and their Markdown report.

One :class:`Record` per (problem, solver) run; :func:`report` turns them into the
per-family table (success rate and median time per solver, fccqp's wrong claims)
followed by the lists behind it: every wrong claim, every other fccqp result that
verify_solution rejects, and the problems fccqp fails where Clarabel succeeds.
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass

import numpy as np

from benchmarks.general_suite.families import FAMILIES
from benchmarks.general_suite.runs import SOLVERS

NAMES = {"fccqp": "fccqp", "clarabel": "Clarabel", "osqp": "OSQP", "piqp": "PIQP"}
WRONG_STATUSES = ("solved", "solved_inaccurate")
"""fccqp statuses that promise a point: rejected by verify_solution, a wrong claim."""


@dataclass(frozen=True)
class Record:
    """One run of one solver on one problem, judged."""

    index: int
    family: str
    member: int
    expected: str
    n: int
    m: int
    cones: int
    solver: str
    status: str
    claim: str
    time: float
    success: bool
    objective_error: float
    failed_checks: str
    """The yardstick checks the point fails, ``;``-separated."""
    verified: bool | None
    """Whether verify_solution accepts the result (fccqp only, else None)."""

    @property
    def wrong_claim(self) -> bool:
        """fccqp promised a point that verify_solution rejects."""
        return self.solver == "fccqp" and self.status in WRONG_STATUSES and not self.verified

    def describe(self) -> str:
        return (f"{self.family}[{self.member}] (#{self.index}, n={self.n}, m={self.m}, "
                f"{self.cones} cones, {self.expected})")


def _rate(records: list[Record]) -> str:
    if not records:
        return "—"
    wins = sum(r.success for r in records)
    return f"{wins}/{len(records)} ({100 * wins / len(records):.0f}%)"


def _median_ms(records: list[Record]) -> str:
    return f"{1e3 * np.median([r.time for r in records]):.2f}" if records else "—"


def _row(label: str, records: list[Record]) -> str:
    by_solver = {s: [r for r in records if r.solver == s] for s in SOLVERS}
    problems = len(by_solver["fccqp"])
    wrong = sum(r.wrong_claim for r in by_solver["fccqp"])
    cells = [label, str(problems), *(_rate(by_solver[s]) for s in SOLVERS), str(wrong),
             *(_median_ms(by_solver[s]) for s in SOLVERS)]
    return "| " + " | ".join(cells) + " |"


def summary_table(records: list[Record]) -> str:
    """Per family, over all problems and over the cone-free ones."""
    header = ["family", "problems", *(f"{NAMES[s]} success" for s in SOLVERS),
              "fccqp wrong SOLVED", *(f"{NAMES[s]} median ms" for s in SOLVERS)]
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for family in FAMILIES:
        members = [r for r in records if r.family == family]
        if members:
            lines.append(_row(family, members))
    lines.append(_row("**all**", records))
    lines.append(_row("**all without cones**", [r for r in records if r.cones == 0]))
    return "\n".join(lines)


def wrong_claims(records: list[Record]) -> list[str]:
    """One line per fccqp wrong claim."""
    return [f"- {r.describe()}: {r.status}, fails {r.failed_checks or 'verify only'}"
            for r in records if r.wrong_claim]


def other_rejections(records: list[Record]) -> list[str]:
    """One line per fccqp result of another status that verify_solution rejects
    (a certificate, or ``A x = b`` at an iteration limit)."""
    return [f"- {r.describe()}: {r.status}" for r in records
            if r.solver == "fccqp" and r.verified is False and not r.wrong_claim
            and not r.status.startswith("error")]


def fccqp_fails_clarabel_succeeds(records: list[Record]) -> dict[str, list[str]]:
    """Family -> one line per problem fccqp fails and Clarabel succeeds on."""
    clarabel_wins = {r.index for r in records if r.solver == "clarabel" and r.success}
    out: dict[str, list[str]] = defaultdict(list)
    for r in records:
        if r.solver == "fccqp" and not r.success and r.index in clarabel_wins:
            why = r.failed_checks or (f"objective off by {r.objective_error:.1e}"
                                      if r.claim == "solved" else "")
            out[r.family].append(f"{r.member} (#{r.index}, n={r.n}): {r.status}"
                                 + (f"; {why}" if why else ""))
    return out


def report(records: list[Record], missing_references: int) -> str:
    """The Markdown report: the table, then the lists behind it."""
    parts = ["## General-QP suite at eps 1e-6", "", summary_table(records), "",
             "Success: claimed solved, the point meets the 1e-6 yardstick "
             "(benchmarks/general_suite/yardstick.py) and the objective is within 1e-6 of "
             "the Clarabel reference (tol 1e-10); on infeasible problems, the right "
             "infeasibility claimed. OSQP and PIQP run on the cone-free problems only; "
             "Clarabel through qpsolvers, except on problems with cones or with no "
             "constraint (its own API). Times: median wall time of the whole call.", ""]
    if missing_references:
        parts += [f"{missing_references} feasible problems have no reference (Clarabel "
                  "failed at 1e-10): judged on the yardstick alone.", ""]
    wrong = wrong_claims(records)
    parts += ["### fccqp SOLVED (or SOLVED_INACCURATE) rejected by verify_solution", ""]
    parts += wrong or ["none"]
    parts += ["", "### fccqp results of other statuses rejected by verify_solution", ""]
    parts += other_rejections(records) or ["none"]
    parts += ["", "### fccqp fails where Clarabel succeeds", ""]
    fails = fccqp_fails_clarabel_succeeds(records)
    for family, lines in fails.items():
        parts += [f"- **{family}**: {len(lines)}", *(f"  - {line}" for line in lines)]
    if not fails:
        parts.append("none")
    return "\n".join(parts) + "\n"
