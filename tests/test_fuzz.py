"""A fixed subset of the fuzzer of issue 26 ("Honest verdicts on every problem").

Every case of :data:`SEEDS` runs on every dense KKT backend, those of
:data:`SPARSE_SEEDS` on the sparse path too (slower per iteration: its cases are ones
that end early). Each asserts that fccqp answered honestly: :func:`fuzzing.judge`
returns ``None``. Some seeds are the reproducers that ``tools/fuzz_campaign.py``
found; replay one with ``python tools/fuzz_campaign.py --replay class:seed
--backend NAME``.
"""

from __future__ import annotations

import pytest

from fuzzing import CLASSES, Case, judge

DENSE_BACKENDS = ("auto", "schur_reduced", "ldl_reduced", "ldl_full")
"""The dense backends of ``fccqp.settings.KKT_BACKENDS``."""

SEEDS = {
    "bad_input": (0, 1, 2, 3, 4, 5),
    "feasible": (0, 1, 2, 3, 4, 5),
    "primal_infeasible": (0, 1, 2, 3, 80, 146, 177, 182, 350, 100094, 300345),
    "dual_infeasible": (0, 1, 2, 33, 166, 257, 368),
    "solver_reuse": (0, 1, 2, 50, 164, 211, 100008, 100206, 500061, 700137),
    "extreme_data": (0, 1, 7, 9, 38, 47, 56, 108, 138, 149, 202, 214, 254, 302, 308, 316,
                     311, 326, 335, 337, 355, 363, 365, 489, 1182, 2244, 100082, 100180, 100213,
                     100228, 100233, 500030, 500064, 500099, 500322, 700281, 900343, 900360,
                     1100037, 1100057, 1100150, 1100253, 1300030, 1300300, 1500043, 1700106,
                     1700359),
    "qpsolvers": (0, 1, 2, 1700123),
    "cvxpy": (1, 2, 3),
}
"""Seeds per class run on every dense backend: a passing case or two per class and the
reproducers of the failure mechanisms the campaign found at ed3b90e, 836ab4b, 5f3a658,
16f1696 and 206a4f0 (seeds from 100000, and extreme_data 489, 1182, 2244 of the deep
``--classes extreme_data`` run; 1100037, 1100057, 1100253 are the same mechanisms on a
seed unseen by their fix; 1300300 an infeasibility claim at the data's rounding;
1100150 inconsistent rows under a huge ``q``; 1300030, 1500043, 1700106, 1700359 and
qpsolvers 1700123 stalls that a forced backend now solves again at another rho or
unequilibrated; issues 26 and 28)."""

SPARSE_SEEDS = {
    "bad_input": (0, 1, 2),
    "feasible": (0,),
    "solver_reuse": (38,),
    "extreme_data": (26,),
    "qpsolvers": (100035,),
    "cvxpy": (7, 1700154),
    "dual_infeasible": (1700072,),
}
"""Seeds per class run on the sparse path (each ends within a few dozen iterations);
``qpsolvers:100035`` is an LP that the compressed-column polish lost at
``POLISH_CSC_DELTA = 1e-12`` (qdldl without pivoting); ``cvxpy:1700154`` a zero pivot
that ``qdldl``'s update did not report, ``dual_infeasible:1700072`` solves whose first
block was left unrefined (both diverged to NUMERICAL_ERROR on unbounded problems)."""

OPEN: dict[str, str] = {}
"""Reproducers of mechanisms still open (issue 26), each the reason it fails: expected
to fail (strictly) on the backends where it does, so that a fix turns them red (none
open now)."""
OPEN_BACKENDS: dict[str, tuple[str, ...]] = {}
"""Where an open case fails on some backends only."""


def _case(name: str, seed: int, backend: str):
    key = f"{name}:{seed}"
    if key in OPEN and backend in OPEN_BACKENDS.get(key, (*DENSE_BACKENDS, "sparse")):
        return pytest.param(name, seed, backend, id=f"{key}-{backend}",
                            marks=pytest.mark.xfail(strict=True, reason=OPEN[key]))
    return pytest.param(name, seed, backend, id=f"{key}-{backend}")


CASES = [_case(name, seed, backend) for backend in DENSE_BACKENDS
         for name, seeds in SEEDS.items() for seed in seeds]
CASES += [_case(name, seed, "sparse") for name, seeds in SPARSE_SEEDS.items() for seed in seeds]


def test_every_class_is_covered() -> None:
    assert set(SEEDS) == set(CLASSES)


@pytest.mark.parametrize(("name", "seed", "backend"), CASES)
def test_fuzz_case(name: str, seed: int, backend: str) -> None:
    failure = judge(Case.of(name, seed), backend)
    assert failure is None, failure
