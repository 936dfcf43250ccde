"""fccqp on the general-QP suite (benchmarks/general_suite): never a claim verify rejects.

Runs the first :data:`SUBSET` problems of the suite (every family is interleaved into
them) through fccqp at the benchmark's settings, and checks the generator and the
benchmark's yardstick on the way: problems are reproducible from their seeds, their
kinds by construction agree with Clarabel, the slack form of the qpsolvers problems
keeps their known optima, and the yardstick rejects a perturbed point.
"""

from __future__ import annotations

import numpy as np
import pytest
import qpsolvers.problems
from benchmarks.general_suite.families import FAMILIES, FEASIBLE, build, suite
from benchmarks.general_suite.runs import run, run_fccqp
from benchmarks.general_suite.yardstick import point_failures, verified

from fccqp import Status
from reference import clarabel_solve

SUBSET = 120
ITEMS = suite(SUBSET)
IDS = [f"{item.family}[{item.member}]" for item in ITEMS]
CLAIMS_A_POINT = (Status.SOLVED, Status.SOLVED_INACCURATE)


@pytest.mark.parametrize("item", ITEMS, ids=IDS)
def test_fccqp_never_claims_a_point_verify_rejects(item, kkt_backend):
    """On every KKT backend (tests/conftest.py)."""
    outcome = run_fccqp(item.problem, kkt_backend)  # raises anything but ValueError / TypeError
    if outcome.result is None:
        assert outcome.status.startswith("error: ")
        return
    status = outcome.result.status
    if item.expected != FEASIBLE:
        assert status not in CLAIMS_A_POINT, f"{item.describe()} reported {status}"
    if status in CLAIMS_A_POINT:
        assert verified(item, outcome), item.describe()


def test_suite_size_and_families():
    assert sum(count for count, _ in FAMILIES.values()) >= 500
    assert {item.family for item in ITEMS} == set(FAMILIES)


def test_problems_regenerate_from_their_seeds():
    for item in ITEMS[::7]:
        again = build(item.family, item.member)
        assert again.index == item.index and again.expected == item.expected
        for mine, theirs in zip(item.problem.args(), again.problem.args(), strict=True):
            if isinstance(mine, np.ndarray):
                np.testing.assert_array_equal(mine, theirs)
            else:
                assert mine == theirs


@pytest.mark.parametrize("item", ITEMS, ids=IDS)
def test_kind_by_construction_agrees_with_clarabel(item):
    assert clarabel_solve(*item.problem.args()).status == (
        "solved" if item.expected == FEASIBLE else item.expected)


@pytest.mark.parametrize("member", range(6))
def test_slack_form_keeps_the_known_optimum(member):
    # the first six qpsolvers members come with their solutions (the QPGUR ones do not)
    getter = ("get_qpsut01", "get_qpsut02", "get_qpsut03", "get_qpsut04", "get_qpsut05",
              "get_qptest")[member]
    known, solution = getattr(qpsolvers.problems, getter)()
    P, q = np.atleast_2d(known.P), np.asarray(known.q).reshape(-1)
    expected = 0.5 * solution.x @ P @ solution.x + q @ solution.x
    reference = clarabel_solve(*build("qpsolvers", member).problem.args())
    assert reference.obj == pytest.approx(expected, rel=1e-6, abs=1e-6)


def test_yardstick_accepts_a_solution_and_rejects_a_perturbed_one():
    item = build("friction", 3)
    outcome = run("clarabel", item.problem)
    assert not point_failures(item, outcome)
    moved = type(outcome)(**{**outcome.__dict__, "x": outcome.x + 1e-3})
    assert point_failures(item, moved)
