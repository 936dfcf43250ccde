"""The status of the returned point: what a run that ended without an answer tries
next, and no claim that the returned point does not keep.

Each test is a mechanism that left a fuzz case (``tools/fuzz_campaign.py``, backend
auto) failing: a solvable QP returned NUMERICAL_ERROR or MAX_ITER_REACHED, or a
claimed status whose point fails :func:`verify.verify_solution`. Results are judged
by ``verify_solution`` and by the fuzzer's judge (Clarabel's answer as reference).
"""

from __future__ import annotations

import numpy as np
import pytest

import fccqp
from fccqp import Status
from fuzzing import Case, judge
from verify import verify_solution

DENSE_BACKENDS = ["auto", "schur_reduced", "ldl_reduced", "ldl_full"]
"""Every dense ``kkt_backend``."""


def _solved(case: str, **settings) -> fccqp.Result:
    """fccqp's result on the fuzz ``case`` (``class:seed``), judged by verify_solution."""
    problem = Case.parse(case).scenario().problem
    result = fccqp.solve(*problem.args(), **settings)
    verify_solution(problem, result)
    return result


def test_a_polished_point_that_loses_the_iterates_status_is_not_kept():
    """``P`` of 9e16 (fuzz extreme_data:1100169): the iterate is solved at 11
    iterations; its polished point has smaller residuals but an entry bounded above by
    -2.5e-8 at 1.0e-4, within the set tolerance of entries of 71 and far outside its
    own size in the scaled units, so the status could not stand on it and the run
    ended NUMERICAL_ERROR. The polished point is not kept then, in the form the run
    chose (no other form tried)."""
    result = _solved("extreme_data:1100169", kkt_backend="ldl_full")
    assert result.status is Status.SOLVED
    assert result.backend == "ldl_full"
    assert judge(Case.parse("extreme_data:1100169"), "auto") is None


@pytest.mark.parametrize("backend", DENSE_BACKENDS)
@pytest.mark.parametrize("case", ["extreme_data:1100361", "extreme_data:2500055"])
def test_a_qp_without_constrained_entries_is_iterated_to_its_optimum(case, backend):
    """No box entry nor cone, ``q`` of 4e11 / 2.4e12 orthogonal to the rays of ``[P; A]``
    to rounding, the optimum at 1e11 / 2e13: the start's proximal steps read as a ray,
    the ray test failed, and the run ended MAX_ITER_REACHED at 0 iterations. It now goes
    on with proximal steps to the optimum, on every dense backend. At 2e13 (2500055)
    ``A x`` of 1.2 is a sum of terms of 3e13 whose rounding (7e-3) exceeds ``eps_rel
    max(|A x|, |b|)``: the returned point passes at the rounding of its terms (which
    ``verify`` allows to 1e-9 of them), else it stays MAX_ITER_REACHED at 4000."""
    result = _solved(case, kkt_backend=backend)
    assert result.status is Status.SOLVED
    assert result.iterations > 0
    assert judge(Case.parse(case), backend) is None


def test_an_equality_qp_along_a_ray_is_still_certified():
    """The same iteration certifies a ray that the start did not: ``P`` singular on
    the null space of ``A``, ``q`` along that null direction."""
    import numpy as np

    from verify import Problem

    rng = np.random.default_rng(3)
    n = 6
    M = rng.standard_normal((n, 3))
    A = rng.standard_normal((2, n))
    null = np.linalg.svd(np.vstack([M.T, A]))[2][-1]   # P null = 0, A null = 0
    problem = Problem.of(M @ M.T, -null + 1e-3 * rng.standard_normal(n) @ M @ M.T,
                         A, A @ rng.standard_normal(n))
    result = fccqp.solve(*problem.args())
    verify_solution(problem, result)
    assert result.status is Status.DUAL_INFEASIBLE


@pytest.mark.parametrize("max_iter", [3999, 4000])
def test_a_summed_gap_that_cancels_is_no_claim(max_iter):
    """A linear program with ``q`` of 2.4e17 and entries of 1e11 (fuzz
    extreme_data:1900288): the iterates stall; after the final ``A x = b`` correction
    the summed gap (2.7e12) passed while a cone block's ``x'z`` was 1.8e14, 1e-14 of
    the products' terms and beyond what the status promises, and the run was returned
    SOLVED (3999 iterations) or SOLVED_INACCURATE (4000). No status claims the
    tolerances on such a point now: a claimed point's cone block keeps ``|x'z|`` within
    the status's gap tolerance (10x for SOLVED_INACCURATE) beside the rounding of its
    terms (1e-15 of ``|x|'|z|``, a few ulps; the point above was 1e-14 of them). The run
    stopped at 3999 may end SOLVED_INACCURATE on its final polish's point (``x'z``
    1.2e13, 1e-16 of its terms); Clarabel's answer is unproven there."""
    problem = Case.parse("extreme_data:1900288").scenario().problem
    result = _solved("extreme_data:1900288", max_iter=max_iter)
    if result.status in (Status.SOLVED, Status.SOLVED_INACCURATE):
        P, q = problem.args()[:2]
        x, z = result.x, result.z
        scale = max(1.0, abs(float(q @ x)), abs(float(x @ P @ x)))
        looser = 1.0 if result.status is Status.SOLVED else 10.0
        eps = fccqp.Settings().eps_rel
        for block, _, _ in problem.blocks():
            rounding = 1e-15 * float(np.abs(x[block]) @ np.abs(z[block]))
            assert abs(float(x[block] @ z[block])) <= looser * eps * scale + rounding
    assert judge(Case.parse("extreme_data:1900288"), "auto") is None


def test_a_run_whose_returned_point_fails_is_solved_again_in_the_other_form():
    """``P`` of 1e18 (fuzz extreme_data:2100247): the reduced form's iterate passed at
    277 iterations, and its final ``A x = b`` correction left a cone block of size
    3e-11 outside its cone by 5e-12, beyond the scaled-units guard: NUMERICAL_ERROR.
    Such a run gets a stalled run's second tries; the full form ends SOLVED."""
    result = _solved("extreme_data:2100247")
    assert result.status is Status.SOLVED
    assert judge(Case.parse("extreme_data:2100247"), "auto") is None
