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
    "primal_infeasible": (0, 1, 2, 3, 80),
    "dual_infeasible": (0, 1, 2, 33, 257),
    "solver_reuse": (0, 1, 2, 211),
    "extreme_data": (0, 1, 38, 138, 202, 335),
    "qpsolvers": (0, 1, 2),
    "cvxpy": (1, 2, 3),
}
"""Seeds per class run on every dense backend: a passing case or two per class and the
reproducers of the failure mechanisms the campaign found at ed3b90e (issue 26)."""

SPARSE_SEEDS = {
    "bad_input": (0, 1, 2),
    "feasible": (0,),
    "solver_reuse": (38,),
    "extreme_data": (26,),
}
"""Seeds per class run on the sparse path (each ends within a few dozen iterations)."""

CASES = [(name, seed, backend) for backend in DENSE_BACKENDS
         for name, seeds in SEEDS.items() for seed in seeds]
CASES += [(name, seed, "sparse") for name, seeds in SPARSE_SEEDS.items() for seed in seeds]


def test_every_class_is_covered() -> None:
    assert set(SEEDS) == set(CLASSES)


@pytest.mark.parametrize(("name", "seed", "backend"), CASES,
                         ids=[f"{name}:{seed}-{backend}" for name, seed, backend in CASES])
def test_fuzz_case(name: str, seed: int, backend: str) -> None:
    failure = judge(Case.of(name, seed), backend)
    assert failure is None, failure
