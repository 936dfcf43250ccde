"""Overhead of solving a whole-body-control QP through CVXPY instead of fccqp's API.

The same synthetic WBC-like QP (floating-base dynamics, rigid contacts, torque limits,
friction cones) is solved natively with :mod:`fccqp` and through CVXPY with the
``FCCQP`` plugin, which maps the torque limits to fccqp's box and the
``cp.SOC(mu * f[:, 2], f[:, :2], axis=1)`` constraint to native friction cones. The
script compares fccqp's own solver time, ``Result.solve_time`` against
``problem.solver_stats.solve_time`` (CVXPY's compilation and the translation are not
part of either), as medians over many repetitions, in two regimes:

- cold: every solve from scratch (``fccqp.solve`` vs ``problem.solve(warm_start=False)``);
- warm: a sequence of QPs whose linear cost changes slightly, as in a control loop
  (one ``fccqp.Solver`` vs re-solving a parametrized CVXPY problem).

Run ``python benchmarks/cvxpy_overhead.py [--reps N]``; the target is a ratio within 1.5.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass

import cvxpy as cp
import numpy as np

import fccqp
from fccqp_cvxpy import FCCQP


@dataclass(frozen=True)
class WbcQP:
    """``min 1/2 x'Px + q'x  s.t.  A x = b, lb <= x <= ub, friction cones`` with
    ``x = [vdot (nv), u (nu), f (3k)]`` and each contact force ``(fx, fy, fz)``."""

    P: np.ndarray
    q: np.ndarray
    A: np.ndarray
    b: np.ndarray
    lb: np.ndarray
    ub: np.ndarray
    mu: float
    nv: int
    nu: int
    contacts: int

    @property
    def force_start(self) -> int:
        """Index of the first contact-force entry in ``x``."""
        return self.nv + self.nu

    @property
    def cones(self) -> tuple[fccqp.FrictionCone, ...]:
        """One friction cone per contact, on ``x[force_start + 3 i : + 3]``."""
        return tuple(
            fccqp.FrictionCone(self.force_start + 3 * i, self.mu) for i in range(self.contacts)
        )


def wbc_qp(joints: int = 12, contacts: int = 4, mu: float = 0.6, seed: int = 0) -> WbcQP:
    """A random, feasible WBC-like QP whose friction cones and torque limits are active.

    Dynamics ``M vdot - B u - Jc' f = -h`` and contacts ``Jc vdot = -Jcdot v`` are the
    equalities; a feasible point with forces inside the cones fixes ``h`` and
    ``Jcdot v``. An aggressive task-acceleration target and a reward for tangential
    force pull the optimum onto the cone and torque boundaries. The cost is block
    diagonal over ``(vdot, u, f)``.
    """
    rng = np.random.default_rng(seed)
    nv, nu, nf = joints + 6, joints, 3 * contacts
    root = rng.standard_normal((nv, nv))
    M = root @ root.T / nv + np.eye(nv)
    B = np.vstack([np.zeros((6, nu)), np.eye(nu)])
    Jc = rng.standard_normal((nf, nv))
    vdot0 = rng.standard_normal(nv)
    u0 = rng.uniform(-0.5, 0.5, nu)
    f0 = np.tile([0.0, 0.0, 1.0], contacts) * rng.uniform(5.0, 10.0, nf)
    A = np.block([[M, -B, -Jc.T], [Jc, np.zeros((nf, nu + nf))]])
    b = A @ np.concatenate([vdot0, u0, f0])
    Jt = rng.standard_normal((nv, nv))
    target = Jt @ vdot0 + 20.0 * rng.standard_normal(nv)
    P = np.zeros((nv + nu + nf, nv + nu + nf))
    P[:nv, :nv] = Jt.T @ Jt + 1e-3 * np.eye(nv)
    P[nv:nv + nu, nv:nv + nu] = 1e-3 * np.eye(nu)
    P[nv + nu:, nv + nu:] = 1e-4 * np.eye(nf)
    push = rng.standard_normal((contacts, 3)) * [2.0, 2.0, 0.0]  # asks for tangential force
    q = np.concatenate([-Jt.T @ target, np.zeros(nu), -push.reshape(-1)])
    lb = np.full(nv + nu + nf, -np.inf)
    ub = np.full(nv + nu + nf, np.inf)
    lb[nv:nv + nu], ub[nv:nv + nu] = -10.0, 10.0
    return WbcQP(P, q, A, b, lb, ub, mu, nv, nu, contacts)


def cvxpy_problem(qp: WbcQP) -> tuple[cp.Problem, cp.Parameter]:
    """The QP in CVXPY over one variable, with the linear cost as a parameter."""
    x = cp.Variable(qp.q.shape[0])
    q = cp.Parameter(qp.q.shape[0], value=qp.q)
    torque = x[qp.nv:qp.force_start]
    f = cp.reshape(x[qp.force_start:], (qp.contacts, 3), order="C")
    constraints = [
        qp.A @ x == qp.b,
        torque <= qp.ub[qp.nv:qp.force_start],
        torque >= qp.lb[qp.nv:qp.force_start],
        cp.SOC(qp.mu * f[:, 2], f[:, :2], axis=1),
    ]
    objective = cp.Minimize(0.5 * cp.quad_form(x, qp.P, assume_PSD=True) + q @ x)
    return cp.Problem(objective, constraints), q


def linear_costs(qp: WbcQP, count: int, seed: int = 1) -> list[np.ndarray]:
    """A control-loop-like sequence of linear costs drifting slowly around ``qp.q``."""
    rng = np.random.default_rng(seed)
    drift = np.cumsum(rng.standard_normal((count, qp.q.shape[0])), axis=0)
    return [qp.q * (1.0 + 1e-3 * d) for d in drift]


def time_cold(qp: WbcQP, reps: int, settings: fccqp.Settings) -> tuple[np.ndarray, np.ndarray]:
    """fccqp's solve times, natively and via CVXPY, each solve from scratch."""
    problem, _ = cvxpy_problem(qp)
    native, via = np.empty(reps), np.empty(reps)
    solver = FCCQP(settings)
    for k in range(reps):
        native[k] = fccqp.solve(qp.P, qp.q, qp.A, qp.b, qp.lb, qp.ub, qp.cones,
                                settings).solve_time
        problem.solve(solver=solver, warm_start=False)
        via[k] = problem.solver_stats.solve_time
    return native, via


def time_warm(qp: WbcQP, reps: int, settings: fccqp.Settings) -> tuple[np.ndarray, np.ndarray]:
    """fccqp's solve times, natively and via CVXPY, along a warm-started sequence."""
    problem, q_param = cvxpy_problem(qp)
    native_solver = fccqp.Solver(settings)
    solver = FCCQP(settings)
    native, via = np.empty(reps), np.empty(reps)
    for k, q in enumerate(linear_costs(qp, reps)):
        native[k] = native_solver.solve(qp.P, q, qp.A, qp.b, qp.lb, qp.ub, qp.cones).solve_time
        q_param.value = q
        problem.solve(solver=solver, warm_start=True)
        via[k] = problem.solver_stats.solve_time
    return native, via


def main() -> None:
    """Print median solver times and their ratio for both regimes."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--reps", type=int, default=300, help="solves per regime")
    args = parser.parse_args()
    qp = wbc_qp()
    settings = fccqp.Settings()
    problem, _ = cvxpy_problem(qp)
    problem.solve(solver=FCCQP(settings))  # first-call costs: CVXPY's solve chain
    translation = problem.solver_stats.extra_stats["translation"]
    print(f"WBC QP: {qp.q.shape[0]} variables, {qp.b.shape[0]} equalities, "
          f"{qp.contacts} contacts; via CVXPY: {translation.num_slacks} slacks, "
          f"cones {[type(c).__name__ for c in translation.cones]}")
    for regime, timer in (("cold", time_cold), ("warm", time_warm)):
        native, via = timer(qp, args.reps, settings)
        ratio = np.median(via) / np.median(native)
        print(f"{regime}: native median {1e6 * np.median(native):8.1f} us, "
              f"via CVXPY median {1e6 * np.median(via):8.1f} us, ratio {ratio:.2f}")


if __name__ == "__main__":
    main()
