"""Reproducers the general-QP suite found (benchmarks/general_suite, issue 13).

Each test rebuilds the suite's own problem with ``build(family, member)``, solves it at
the suite's settings (eps 1e-6) and judges the answer with :func:`verify.verify_solution`.
"""

from __future__ import annotations

import pytest
from benchmarks.general_suite.families import build

import fccqp
from fccqp import Status
from verify import Tolerances, equality_bound, primal_violations, verify_solution

pytestmark = pytest.mark.usefixtures("every_kkt_backend")
"""Every test on every KKT backend (tests/conftest.py)."""

EPS = {"eps_abs": 1e-6, "eps_rel": 1e-6}


def _equality_holds(problem, result) -> bool:
    """``A x = b`` to factorization accuracy, which formulation.md promises whatever the
    status (verify_solution checks it only where the status carries no other promise)."""
    violation = primal_violations(problem, result.x)["equality"]
    return violation <= equality_bound(problem, result.x, Tolerances())


@pytest.mark.parametrize("member", [8, 28])
def test_unbounded_without_constrained_entries_is_certified(member):
    """dual_infeasible[8] and [28]: a ray with P d = 0, A d = 0, q'd < 0 and no box or
    cone. The cold start's unbounded solution was tested as the certificate, but it
    carries A x = b and its bounded part (P x, A x at 1e-7 of their terms, the test's
    own tolerance): MAX_ITER_REACHED after 0 iterations, with x = 0 breaking A x = b."""
    problem = build("dual_infeasible", member).problem
    result = fccqp.solve(*problem.args(), **EPS)
    verify_solution(problem, result, Tolerances.of(**EPS))
    assert result.status is Status.DUAL_INFEASIBLE
    assert _equality_holds(problem, result)


def test_uncertified_unbounded_start_satisfies_the_equalities():
    """With a certificate tolerance far below rounding (eps_dual_inf = 1e-300) no
    direction passes, and dual_infeasible[28] ends without a certificate: the point
    returned must still satisfy A x = b (it was the origin, |A x - b| = 4.96)."""
    problem = build("dual_infeasible", 28).problem
    result = fccqp.solve(*problem.args(), eps_dual_inf=1e-300, **EPS)
    assert result.status is Status.MAX_ITER_REACHED
    verify_solution(problem, result, Tolerances.of(**EPS))
    assert _equality_holds(problem, result)


@pytest.mark.parametrize("member", [10, 18, 19, 22, 28, 42, 44, 48])
def test_narrow_boxes_far_from_the_origin_are_solved(member):
    """large_multipliers: every entry boxed to a width of 1e-4..1e-2 about a point of
    size 1, multipliers up to 3e8. Rho adaptation judged the primal residual against
    |x| instead of the box width, kept rho 1e3 times too small, and ADMM ended at
    MAX_ITER_REACHED after 4000 iterations with an iterate whose active set polishing
    could not recover (moved to the origin, 8 of 9 solved in 140-1800 iterations)."""
    problem = build("large_multipliers", member).problem
    result = fccqp.solve(*problem.args(), **EPS)
    verify_solution(problem, result, Tolerances.of(**EPS))
    assert result.status is Status.SOLVED


def test_a_persistent_rho_imbalance_within_the_tolerance_moves_rho():
    """fixed_entries[15]: OSQP's rule asks, update after update, for rho about 3.6x
    larger, less than ``adaptive_rho_tolerance`` (5), and rho stayed 0.1 for the 210
    iterations of the run. A move that persists while the residuals do not halve is
    tried (``tuning.RHO_PERSISTENCE``, on either storage): the run ends at a rho that
    only such a move reaches, with the answer of the rule alone."""
    problem = build("fixed_entries", 15).problem
    settings = fccqp.Settings(**EPS)
    result = fccqp.solve(*problem.args(), settings)
    verify_solution(problem, result, Tolerances.of(**EPS))
    assert result.status is Status.SOLVED
    moved = result.rho / settings.rho
    tolerance = settings.adaptive_rho_tolerance
    assert tolerance**0.5 < moved < tolerance
    assert result.iterations < 200
