"""The reduced form's residual gate: the KKT identity of ``base`` and ``W`` it rests on."""

import numpy as np
import pytest

import fccqp
from fccqp import admm
from problems import random_problem


@pytest.mark.parametrize("seed", range(3))
def test_gate_estimates_the_residuals_of_base_plus_w_u(seed):
    solver = fccqp.Solver(max_iter=3)
    solver.solve(*random_problem(seed, n_box=6))
    p, w = solver._previous.scaled, solver._workspace
    assert w.reduced[0] != admm.FULL
    n, S = p.P.shape[0], p.constrained
    u = np.random.default_rng(seed).standard_normal(S.shape[0])
    x_nu = w.base + w.W @ u
    x, nu = x_nu[:n], x_nu[n:]
    # (x, nu) meets the equalities and the stationarity of the x-update
    assert np.allclose(p.A @ x, p.b, atol=1e-9)
    gradient = np.zeros(n)
    gradient[S] = u - w.rho_vec * x[S]
    assert np.allclose(p.P @ x + p.q + p.A.T @ nu, gradient, atol=1e-8)
    # with z = x_S and y cancelling that gradient both residuals vanish: the gate opens
    w.u[:] = u
    w.z[:] = x[S]
    w.y[:] = -gradient[S]
    assert admm._near_convergence(p, w, 1e-6, 1e-6)
    w.z[0] += 1.0  # primal residual
    assert not admm._near_convergence(p, w, 1e-6, 1e-6)
    w.z[0] -= 1.0
    w.y[-1] += 1.0  # dual residual
    assert not admm._near_convergence(p, w, 1e-6, 1e-6)
