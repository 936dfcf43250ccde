"""Infeasibility certificates for runs that stall on a forced ``kkt_backend``.

A run that ends at MAX_ITER_REACHED asks :func:`fccqp.auxiliary.stalled_certificate`
for a Farkas certificate from the least-distance QP. That QP's solve stops at its own
``eps_abs`` and ``eps_rel``, which do not make its multipliers meet the duality identity
when the distance is a few tolerances: such a solution is solved again to the Farkas
test at any positive distance, not only at distances below ``eps_abs``. Every result is
judged by :func:`verify.verify_solution`; the cases come from the fuzzer (issue 28).
"""

from __future__ import annotations

import pytest

import fccqp
from fccqp import Status
from fuzzing import Case, judge
from verify import verify_solution

REDUCED = ["schur_reduced", "ldl_reduced"]
"""The forced reduced forms, where these least-distance QPs stopped short."""


@pytest.mark.parametrize("backend", REDUCED)
@pytest.mark.parametrize("seed", [1700289, 1700339])
def test_a_least_distance_a_few_tolerances_wide_is_certified_in_the_reduced_forms(
        backend, seed):
    """A friction cone capped through a boxed copy of its normal force (gap 1.2e-4), three
    cones pinned outside their sum (gap 4.5e-3): the run stalls for 4000 iterations, and
    the least-distance QP ended SOLVED in the reduced form at a distance of 13 times
    ``eps_abs`` with its identity unmet, so no certificate; solved again to the Farkas
    tolerances, it certifies the infeasibility that the construction and Clarabel
    state."""
    problem = Case.of("primal_infeasible", seed).scenario().problem
    result = fccqp.solve(*problem.args(), kkt_backend=backend)
    verify_solution(problem, result)
    assert result.status is Status.PRIMAL_INFEASIBLE
    assert result.iterations > 4000   # the stalled run's, then the auxiliary solves'
    assert judge(Case.of("primal_infeasible", seed), backend) is None


@pytest.mark.parametrize("backend", ["ldl_full", *REDUCED])
def test_a_certificate_on_nearly_parallel_rows_is_sought_against_the_rows_terms(backend):
    """A friction cone capped through a boxed copy of its normal force, rows of 1e10
    with two nearly parallel: the plain least distance's certificate cancels the two
    rows' terms to 2.3e-10 of them, below ``SEPARATION_FLOOR``; the least distance with
    the rows softened to their right-hand sides' size
    (:func:`fccqp.auxiliary.relative_distance_problem`) finds one that separates by
    1.8e-4 of its terms, as Clarabel's does."""
    case = Case.of("extreme_data", 1900317)
    problem = case.scenario().problem
    result = fccqp.solve(*problem.args(), kkt_backend=backend)
    verify_solution(problem, result)
    assert result.status is Status.PRIMAL_INFEASIBLE
    assert judge(case, backend) is None
