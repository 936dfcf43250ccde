"""The rho of a timed cold start comes from the data (:func:`fccqp.rho_rule.curvature_rho`):
``COLD_RHO_CURVATURE`` times the geometric mean of the cost's curvature on the
constrained entries once the equalities and free entries are eliminated, in the scaled
units before the cost's normalization, where that is within ``COLD_RHO_RANGE`` of
``settings.rho``. Untimed runs, runs at a fixed rho and QPs outside that range start at
``settings.rho``."""

from __future__ import annotations

import numpy as np
import pytest
from fccqp.tuning import COLD_RHO_CURVATURE, COLD_RHO_RANGE

import fccqp

BOXED = 3
RHO = fccqp.Settings().rho


def task_qp(seed: int, weight: float = 1e6) -> tuple[np.ndarray, ...]:
    """``(P, q, A, b, lb, ub)`` shaped like a control tick's: three boxed "forces" with
    a regularization of 1e-4, three free "accelerations" that equal a random map of them
    and carry a task of ``weight``."""
    rng = np.random.default_rng(seed)
    F = rng.standard_normal((3, 3))
    P = np.diag(np.r_[np.full(3, 1e-4), np.full(3, weight)])
    P[3:, 3:] += 0.1 * weight * F @ F.T
    q = np.r_[np.zeros(3), -weight * rng.standard_normal(3)]
    A = np.hstack([rng.standard_normal((3, 3)), -np.eye(3)])
    b = np.zeros(3)
    lb = np.r_[-np.ones(3), np.full(3, -np.inf)]
    return P, q, A, b, lb, -lb


def data_rho(problem: tuple[np.ndarray, ...], scaling: tuple) -> float:
    """The rule computed here: the Schur complement of the scaled KKT matrix on the
    boxed entries, its diagonal's geometric mean, over the cost's normalization."""
    P, q, A, b, lb, ub = problem
    D, E, c = scaling
    n, m = P.shape[0], A.shape[0]
    K = np.block([[c * D[:, None] * P * D[None, :], (E[:, None] * A * D[None, :]).T],
                  [E[:, None] * A * D[None, :], np.zeros((m, m))]])
    S, free = np.arange(BOXED), np.arange(BOXED, n + m)
    C = K[np.ix_(S, S)] - K[np.ix_(S, free)] @ np.linalg.solve(K[np.ix_(free, free)],
                                                               K[np.ix_(free, S)])
    return COLD_RHO_CURVATURE * np.exp(np.mean(np.log(np.diag(C)))) / c


def started_at(problem: tuple[np.ndarray, ...], **settings: object) -> tuple[float, float]:
    """The rho a first solve (a cold start) started at, from its log, and the rule's."""
    solver = fccqp.Solver(kkt_backend="schur_reduced", verbose=True, **settings)
    assert solver.solve(*problem).status is fccqp.Status.SOLVED
    return solver._workspace.log_lines[0][4], data_rho(problem, solver._workspace.scaling)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_timed_cold_start_begins_at_the_datas_rho(seed, capsys):
    start, rule = started_at(task_qp(seed), time_limit=100.0)
    assert start == pytest.approx(rule, rel=1e-6)
    assert 0.01 < rule < 0.05   # the task's weight sets it: not settings.rho


@pytest.mark.parametrize("settings", [dict(), dict(time_limit=100.0, adaptive_rho=False)])
def test_an_untimed_or_fixed_rho_run_begins_at_settings_rho(settings, capsys):
    assert started_at(task_qp(0), **settings)[0] == RHO


@pytest.mark.parametrize("weight", [1e-2, 1e4])
def test_a_datas_rho_outside_the_fit_is_not_taken(weight, capsys):
    """At a task weight of 1e-2 against the forces' 1e-4 the rule gives about 1e-10; at
    1e4 about 2e-4, below ``settings.rho / COLD_RHO_RANGE`` as talos_reduced's 3.75e-4."""
    start, rule = started_at(task_qp(0, weight=weight), time_limit=100.0)
    assert rule < RHO / COLD_RHO_RANGE
    assert start == RHO
