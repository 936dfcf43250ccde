"""The general-QP suite: 543 seeded problems in fccqp's form, in 12 families.

Every problem is ``min 1/2 x'Px + q'x  s.t.  A x = b, lb <= x <= ub, x[block] in cone``
(a :class:`verify.Problem`) with the kind it has by construction: ``feasible`` (an
optimum exists), ``primal_infeasible`` or ``dual_infeasible`` (unbounded below on a
nonempty feasible set). Feasible problems take ``b = A x0`` for a point ``x0`` inside
the box and the cones, so that redundant and nearly dependent rows stay consistent;
``P`` is positive semidefinite, and positive definite wherever a free direction would
otherwise be unbounded. Sizes ``n`` run from 2 to 500, log-uniform and mostly below 60;
only the ``sizes`` family goes to 200-500 (and QPSUT05 has ``n = 1``).

=====================  =====  ================================================================
family                 count  what
=====================  =====  ================================================================
``ill_conditioned``       60  ``P = Q diag(logspace(0, -c)) Q'``, condition ``10^c`` from 1e2 to
                              1e10 (evenly over the members), random equalities; even members
                              box every entry and push with a random ``q``, odd members box half
                              and take ``q = -P c`` (the unconstrained minimizer ``c`` is finite)
``badly_scaled``          60  a well-conditioned QP with columns scaled by ``10^U(-2, 2)``, the
                              cost by ``10^U(-3, 3)`` and each row of ``A`` to a norm in
                              ``10^U(-4, 4)``
``degenerate_lp``         60  ``P = 0`` on the box ``[0, u]``, equalities with duplicated, scaled
                              and summed (redundant) rows; ``q`` in {-1, 0, 1} (ties), or
                              ``q = A'w`` (every feasible point optimal), or two equal columns
                              with equal costs
``dependent_rows``        50  random equalities plus exact copies, multiples, sums of rows and
                              rows perturbed by ``10^U(-12, -6)`` (nearly dependent), all
                              holding at an optimum chosen first (the KKT conditions built in)
``large_multipliers``     50  every entry boxed to a width ``10^U(-4, 0)`` around ``x0``; even
                              members take ``|q| ~ 10^U(4, 8)``, odd members
                              ``P ~ 10^U(4, 8)`` with its minimizer far outside the box, so that
                              the box multipliers are as large
``sizes``                 40  ``tests/problems.random_problem`` without cones: 32 with ``n`` in
                              2..200, 8 with ``n`` in 200..500
``fixed_entries``         50  every entry boxed, 10-60% of them fixed (``lb == ub``); a third of
                              the members add an equality on fixed entries only, member 0
                              fixes every entry
``second_order``          50  1-4 ``SecondOrderCone`` blocks of size 2-8 plus boxed and free
                              entries; a quarter have ``P = 0`` on the cones with ``q`` inside
                              the dual cone there
``friction``              50  1-5 ``FrictionCone`` blocks, ``mu`` in 0.1..1.5, every other one
                              with a random normal, ``P`` of low rank plus a small ridge, many
                              equalities (as in whole-body control)
``primal_infeasible``     30  a sum of boxed entries set beyond the box; two copies of a row
                              with different right-hand sides; a positive row set negative on
                              ``[0, 1]``; a second-order cone's ``t`` set negative; a friction
                              force set outside its cone (by 1.5-3x)
``dual_infeasible``       30  a ray ``d`` with ``P d = 0``, ``A d = 0``, ``q'd < 0``: free
                              entries; ``d >= 0`` on entries with a lower bound only; ``d`` in a
                              second-order cone; ``d`` along a friction cone's normal
``qpsolvers``             13  the test problems of ``qpsolvers.problems`` (QPSUT01-05, QPTEST,
                              QPGURDU, QPGUREQ, QPGURABS, and the sparse least squares at
                              ``n`` = 5, 10, 50, 100), each ``G x <= h`` as ``G x + s = h``,
                              ``s >= 0`` on slack entries ``s`` appended to ``x``
=====================  =====  ================================================================

The suite interleaves the families (member 0 of each, then member 1, ...), so that any
prefix :func:`suite` ``(count)`` samples every family. Member ``k`` of a family is
generated from ``numpy.random.default_rng((SEED, family number, k))`` alone:
:func:`build` regenerates any one problem without the others.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import qpsolvers
import qpsolvers.problems
import scipy.sparse as sp

from fccqp import FrictionCone, SecondOrderCone
from problems import random_problem
from verify import Problem

SEED = 20240613
"""Root of every family's seeds."""

FEASIBLE = "feasible"
PRIMAL_INFEASIBLE = "primal_infeasible"
DUAL_INFEASIBLE = "dual_infeasible"


@dataclass(frozen=True)
class SuiteProblem:
    """One problem of the suite and what is known about it by construction."""

    index: int
    """Position in :func:`suite`."""
    family: str
    member: int
    """Position within the family: ``build(family, member)`` regenerates it."""
    expected: str
    """:data:`FEASIBLE`, :data:`PRIMAL_INFEASIBLE` or :data:`DUAL_INFEASIBLE`."""
    problem: Problem

    def describe(self) -> str:
        """``family[member] (#index): n, m, cones``, for tables and reproducers."""
        p = self.problem
        return (f"{self.family}[{self.member}] (#{self.index}): n={p.n}, m={p.b.shape[0]}, "
                f"{len(p.cones)} cones, expected {self.expected}")


# --- building blocks ---------------------------------------------------------------

def _log_int(rng: np.random.Generator, low: int, high: int) -> int:
    """An integer in ``[low, high]``, log-uniform."""
    return int(np.clip(round(np.exp(rng.uniform(np.log(low), np.log(high)))), low, high))


def _orthogonal(rng: np.random.Generator, n: int) -> np.ndarray:
    return np.linalg.qr(rng.standard_normal((n, n)))[0]


def _pd(rng: np.random.Generator, n: int, ridge: float = 0.1) -> np.ndarray:
    """A random positive definite ``M M'/n + ridge I``."""
    M = rng.standard_normal((n, n))
    return M @ M.T / n + ridge * np.eye(n)


def _box_around(rng: np.random.Generator, x0: np.ndarray, entries: np.ndarray,
                width: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Bounds on ``entries`` that hold ``x0`` with a margin, infinite elsewhere."""
    n = x0.shape[0]
    lb, ub = np.full(n, -np.inf), np.full(n, np.inf)
    lb[entries] = x0[entries] - width * rng.uniform(0.1, 1.0, entries.size)
    ub[entries] = x0[entries] + width * rng.uniform(0.1, 1.0, entries.size)
    return lb, ub


def _some(rng: np.random.Generator, n: int, fraction: float) -> np.ndarray:
    """A random subset of ``range(n)`` of about ``fraction * n`` entries."""
    return np.sort(rng.permutation(n)[: int(round(fraction * n))])


def _rows(rng: np.random.Generator, m: int, n: int) -> np.ndarray:
    return rng.standard_normal((m, n))


def _feasible(P, q, A, x0, lb, ub, cones=()) -> tuple[Problem, str]:
    return Problem.of(P, q, A, A @ x0, lb, ub, cones), FEASIBLE


# --- families ----------------------------------------------------------------------

def ill_conditioned(rng: np.random.Generator, k: int, count: int) -> tuple[Problem, str]:
    n = _log_int(rng, 5, 60)
    exponent = 2 + 8 * k / (count - 1)
    Q = _orthogonal(rng, n)
    P = Q @ np.diag(np.logspace(0, -exponent, n)) @ Q.T
    P = (P + P.T) / 2
    x0 = rng.standard_normal(n)
    A = _rows(rng, int(rng.integers(0, n // 3 + 1)), n)
    if k % 2 == 0:
        lb, ub = _box_around(rng, x0, np.arange(n))
        q = 10 * rng.standard_normal(n)
    else:
        lb, ub = _box_around(rng, x0, _some(rng, n, 0.5))
        q = -P @ (x0 + rng.standard_normal(n))
    return _feasible(P, q, A, x0, lb, ub)


def badly_scaled(rng: np.random.Generator, k: int, count: int) -> tuple[Problem, str]:
    n = _log_int(rng, 4, 60)
    m = int(rng.integers(1, n // 2 + 1))
    P, q, x0 = _pd(rng, n), rng.standard_normal(n), rng.standard_normal(n)
    lb, ub = _box_around(rng, x0, _some(rng, n, 0.6))
    A = _rows(rng, m, n)
    d = 10.0 ** rng.uniform(-2, 2, n)           # x = d * u in the new variables u
    cost = 10.0 ** rng.uniform(-3, 3)
    A = A * d
    A *= (10.0 ** rng.uniform(-4, 4, m) / np.linalg.norm(A, axis=1))[:, None]
    return _feasible(cost * d[:, None] * P * d[None, :], cost * d * q, A, x0 / d, lb / d, ub / d)


def degenerate_lp(rng: np.random.Generator, k: int, count: int) -> tuple[Problem, str]:
    n = _log_int(rng, 4, 60)
    u = rng.uniform(1, 3, n)
    A = _rows(rng, int(rng.integers(1, max(2, n // 3) + 1)), n)
    if k % 3 == 2:                              # two equal columns with equal costs
        A[:, 1] = A[:, 0]
        u[1] = u[0]
    x0 = u * rng.uniform(0.2, 0.8, n)
    rows = [A, A[:1], 3 * A[-1:], A[:1] + A[-1:]]  # a copy, a multiple, a sum
    A = np.vstack(rows[: 1 + int(rng.integers(1, 4))])
    if k % 3 == 0:
        q = rng.integers(-1, 2, n).astype(float)
    elif k % 3 == 1:
        q = A.T @ rng.standard_normal(A.shape[0])
    else:
        q = rng.standard_normal(n)
        q[1] = q[0]
    return _feasible(np.zeros((n, n)), q, A, x0, np.zeros(n), u)


def dependent_rows(rng: np.random.Generator, k: int, count: int) -> tuple[Problem, str]:
    """Built around a known optimum ``x*`` (KKT conditions by construction), so that the
    nearly dependent rows, which are new constraints however small their difference,
    hold at ``x*`` with zero multipliers and leave the optimum unchanged."""
    n = _log_int(rng, 5, 60)
    base = _rows(rng, int(rng.integers(1, n // 2 + 1)), n)
    pick = lambda: base[rng.integers(base.shape[0])]  # noqa: E731
    extra = [pick() for _ in range(int(rng.integers(1, 4)))]
    extra += [rng.choice([2.0, -0.5, 1e3]) * pick() for _ in range(int(rng.integers(0, 3)))]
    extra += [pick() + pick() for _ in range(int(rng.integers(0, 3)))]
    extra += [pick() + 10.0 ** rng.uniform(-12, -6) * rng.standard_normal(n)
              for _ in range(int(rng.integers(1, 4)))]
    x_star = rng.standard_normal(n)
    lb, ub = _box_around(rng, x_star, _some(rng, n, 0.5))
    z = np.zeros(n)
    at_lb, at_ub = _some(rng, n, 0.2), _some(rng, n, 0.2)
    at_lb = at_lb[np.isfinite(lb[at_lb])]
    at_ub = np.setdiff1d(at_ub[np.isfinite(ub[at_ub])], at_lb)
    x_star[at_lb], z[at_lb] = lb[at_lb], -rng.uniform(0.1, 2.0, at_lb.size)
    x_star[at_ub], z[at_ub] = ub[at_ub], rng.uniform(0.1, 2.0, at_ub.size)
    P = _pd(rng, n, 0.01)
    q = -(P @ x_star + base.T @ rng.standard_normal(base.shape[0]) + z)
    A = np.vstack([base, *extra])[rng.permutation(base.shape[0] + len(extra))]
    return _feasible(P, q, A, x_star, lb, ub)


def large_multipliers(rng: np.random.Generator, k: int, count: int) -> tuple[Problem, str]:
    n = _log_int(rng, 3, 50)
    x0 = rng.standard_normal(n)
    lb, ub = _box_around(rng, x0, np.arange(n), width=10.0 ** rng.uniform(-4, 0))
    A = _rows(rng, int(rng.integers(0, n // 3 + 1)), n)
    size = 10.0 ** rng.uniform(4, 8)
    if k % 2 == 0:
        P, q = _pd(rng, n), size * rng.standard_normal(n)
    else:
        P = size * _pd(rng, n)
        q = -P @ (x0 + 10 * rng.standard_normal(n))
    return _feasible(P, q, A, x0, lb, ub)


def sizes(rng: np.random.Generator, k: int, count: int) -> tuple[Problem, str]:
    n = _log_int(rng, 2, 200) if k < count - 8 else int(rng.integers(200, 501))
    m = int(rng.integers(0, n // 4 + 1))
    seed = int(rng.integers(2**31))
    P, q, A, b, lb, ub, _ = random_problem(seed, n=n, m=m, n_cones=0,
                                           n_box=int(rng.integers(0, n + 1)))
    return Problem.of(P, q, A, b, lb, ub), FEASIBLE


def fixed_entries(rng: np.random.Generator, k: int, count: int) -> tuple[Problem, str]:
    n = _log_int(rng, 3, 60)
    x0 = rng.standard_normal(n)
    lb, ub = _box_around(rng, x0, np.arange(n))
    fixed = np.arange(n) if k == 0 else _some(rng, n, rng.uniform(0.1, 0.6))
    lb[fixed] = ub[fixed] = x0[fixed]
    A = _rows(rng, int(rng.integers(0, n // 3 + 1)), n)
    if k % 3 == 1 and fixed.size:
        only_fixed = np.zeros((1, n))
        only_fixed[0, fixed] = rng.standard_normal(fixed.size)
        A = np.vstack([A, only_fixed])
    return _feasible(_pd(rng, n), 3 * rng.standard_normal(n), A, x0, lb, ub)


def _cone_layout(rng: np.random.Generator, dims: list[int]) -> tuple[int, int, int]:
    """``(entries in cones, boxed entries, free entries)`` for blocks of ``dims``."""
    return sum(dims), int(rng.integers(0, 11)), int(rng.integers(0, 11))


def second_order(rng: np.random.Generator, k: int, count: int) -> tuple[Problem, str]:
    dims = [int(d) for d in rng.integers(2, 9, int(rng.integers(1, 5)))]
    c, nb, nf = _cone_layout(rng, dims)
    n = c + nb + nf
    starts = np.cumsum([0, *dims[:-1]])
    cones = [SecondOrderCone(int(s), d) for s, d in zip(starts, dims, strict=True)]
    x0 = rng.standard_normal(n)
    for s, d in zip(starts, dims, strict=True):
        x0[s] = np.linalg.norm(x0[s + 1 : s + d]) + rng.uniform(0.1, 1.0)
    lb, ub = _box_around(rng, x0, np.arange(c, c + nb))
    q = 3 * rng.standard_normal(n)
    P = _pd(rng, n)
    if k % 4 == 3:                              # linear on the cones, bounded by q in K*
        P[:c, :] = P[:, :c] = 0.0
        for s, d in zip(starts, dims, strict=True):
            q[s] = np.linalg.norm(q[s + 1 : s + d]) + rng.uniform(0.1, 1.0)
    A = _rows(rng, int(rng.integers(0, n // 3 + 1)), n)
    return _feasible(P, q, A, x0, lb, ub, cones)


def _unit(rng: np.random.Generator) -> np.ndarray:
    v = rng.standard_normal(3)
    return v / np.linalg.norm(v)


def friction(rng: np.random.Generator, k: int, count: int) -> tuple[Problem, str]:
    contacts = int(rng.integers(1, 6))
    c, nb, nf = _cone_layout(rng, [3] * contacts)
    n = c + nb + nf
    x0 = rng.standard_normal(n)
    cones = []
    for j in range(contacts):
        normal = _unit(rng) if j % 2 else np.array([0.0, 0.0, 1.0])
        cones.append(FrictionCone(3 * j, float(rng.uniform(0.1, 1.5)),
                                  tuple(normal) if j % 2 else None))
        x0[3 * j : 3 * j + 3] = normal * rng.uniform(0.5, 2.0)
    lb, ub = _box_around(rng, x0, np.arange(c, c + nb))
    M = rng.standard_normal((n, max(1, n // 2)))
    P = M @ M.T / M.shape[1] + 10.0 ** rng.uniform(-4, 0) * np.eye(n)
    A = _rows(rng, int(rng.integers(0, n // 2 + 1)), n)
    return _feasible(P, 3 * rng.standard_normal(n), A, x0, lb, ub, cones)


def primal_infeasible(rng: np.random.Generator, k: int, count: int) -> tuple[Problem, str]:
    n = _log_int(rng, 3, 40)
    P, q = _pd(rng, n), rng.standard_normal(n)
    lb, ub, cones = np.zeros(n), np.ones(n), []
    variant = k % 5
    if variant == 0:                            # sum x = n + 0.5..2 on [0, 1]^n
        A, b = np.ones((1, n)), np.array([n + rng.uniform(0.5, 2.0)])
    elif variant == 1:                          # a row twice, with different b
        A = _rows(rng, int(rng.integers(1, n // 2 + 1)), n)
        b = A @ rng.uniform(0, 1, n)
        A = np.vstack([A, A[:1]])
        b = np.append(b, b[0] + rng.uniform(0.1, 1.0) * max(1.0, abs(b[0])))
    elif variant == 2:                          # a'x < 0 with a > 0 on [0, 1]^n
        A, b = rng.uniform(0.1, 1.0, (1, n)), np.array([-rng.uniform(0.1, 1.0)])
    else:
        d = 3 if variant == 4 else int(rng.integers(2, min(n, 6) + 1))
        n = max(n, d)
        P, q = _pd(rng, n), rng.standard_normal(n)
        lb, ub = np.full(n, -np.inf), np.full(n, np.inf)
        lb[d:], ub[d:] = -1.0, 1.0
        if variant == 3:                        # the cone's t set negative
            cones = [SecondOrderCone(0, d)]
            A, b = np.eye(n)[:1], np.array([-rng.uniform(0.1, 2.0)])
        else:                                   # a friction force outside its cone
            mu = float(rng.uniform(0.1, 1.5))
            cones = [FrictionCone(0, mu)]
            tangential = _unit(rng)[:2]
            tangential /= np.linalg.norm(tangential)
            normal_force = rng.uniform(0.5, 2.0)
            force = np.append(tangential * mu * normal_force * rng.uniform(1.5, 3.0),
                              normal_force)
            A, b = np.eye(n)[:3], force
    return Problem.of(P, q, A, b, lb, ub, cones), PRIMAL_INFEASIBLE


def dual_infeasible(rng: np.random.Generator, k: int, count: int) -> tuple[Problem, str]:
    n = _log_int(rng, 3, 40)
    variant = k % 4
    lb, ub, cones = np.full(n, -np.inf), np.full(n, np.inf), []
    x0 = rng.standard_normal(n)
    d = np.zeros(n)
    if variant == 0:                            # a free direction
        d = rng.standard_normal(n)
    elif variant == 1:                          # d >= 0 where only a lower bound exists
        ray = _some(rng, n, 0.5)
        ray = ray if ray.size else np.array([0])
        d[ray] = rng.uniform(0.1, 1.0, ray.size)
        lb, ub = _box_around(rng, x0, np.arange(n))
        ub[ray] = np.inf
    else:                                       # d in a cone at the start of x
        size = 3 if variant == 3 else int(rng.integers(2, 6))
        n = max(n, size)
        x0, d = rng.standard_normal(n), np.zeros(n)
        lb, ub = _box_around(rng, x0, np.arange(size, n))
        lb[:size], ub[:size] = -np.inf, np.inf
        if variant == 2:
            cones = [SecondOrderCone(0, size)]
            d[1:size] = rng.standard_normal(size - 1)
            d[0] = np.linalg.norm(d[1:size]) * rng.uniform(1.0, 2.0) + 0.1
            x0[0] = np.linalg.norm(x0[1:size]) + 1.0
        else:
            normal = _unit(rng)
            cones = [FrictionCone(0, float(rng.uniform(0.1, 1.5)), tuple(normal))]
            d[:3] = x0[:3] = normal
    unit = d / np.linalg.norm(d)
    project = np.eye(n) - np.outer(unit, unit)  # P d = 0 and A d = 0
    M = project @ rng.standard_normal((n, n))
    P = M @ M.T / n
    A = _rows(rng, int(rng.integers(0, n // 3 + 1)), n) @ project
    q = rng.standard_normal(n)
    q -= (q @ unit + rng.uniform(0.5, 2.0)) * unit  # q'd < 0
    return Problem.of(P, q, A, A @ x0, lb, ub, cones), DUAL_INFEASIBLE


_QPSOLVERS_PROBLEMS: tuple[Callable[[], qpsolvers.Problem], ...] = (
    *(lambda f=f: f()[0] for f in (
        qpsolvers.problems.get_qpsut01, qpsolvers.problems.get_qpsut02,
        qpsolvers.problems.get_qpsut03, qpsolvers.problems.get_qpsut04,
        qpsolvers.problems.get_qpsut05, qpsolvers.problems.get_qptest,
        qpsolvers.problems.get_qpgurdu, qpsolvers.problems.get_qpgureq,
        qpsolvers.problems.get_qpgurabs)),
    *(lambda n=n: qpsolvers.Problem(*qpsolvers.problems.get_sparse_least_squares(n))
      for n in (5, 10, 50, 100)),
)


def with_slacks(problem: qpsolvers.Problem) -> Problem:
    """A qpsolvers problem in fccqp's form, exactly: ``x' = (x, s)`` with
    ``G x + s = h`` and ``s >= 0``, the other parts unchanged."""
    dense = lambda M: None if M is None else np.asarray(  # noqa: E731
        M.toarray() if sp.issparse(M) else M, float)
    P, q, G, h, A, b, lb, ub = (dense(v) for v in problem.unpack())
    n = q.shape[0]
    G, h = (np.zeros((0, n)), np.zeros(0)) if G is None else (G.reshape(-1, n), h.reshape(-1))
    A, b = (np.zeros((0, n)), np.zeros(0)) if A is None else (A.reshape(-1, n), b.reshape(-1))
    k = G.shape[0]
    P_ext = np.zeros((n + k, n + k))
    P_ext[:n, :n] = P.reshape(n, n)
    return Problem.of(
        P_ext, np.concatenate([q, np.zeros(k)]),
        np.block([[A, np.zeros((A.shape[0], k))], [G, np.eye(k)]]), np.concatenate([b, h]),
        np.concatenate([np.full(n, -np.inf) if lb is None else lb, np.zeros(k)]),
        np.concatenate([np.full(n, np.inf) if ub is None else ub, np.full(k, np.inf)]),
    )


def from_qpsolvers(rng: np.random.Generator, k: int, count: int) -> tuple[Problem, str]:
    return with_slacks(_QPSOLVERS_PROBLEMS[k]()), FEASIBLE


Builder = Callable[[np.random.Generator, int, int], tuple[Problem, str]]

FAMILIES: dict[str, tuple[int, Builder]] = {
    "ill_conditioned": (60, ill_conditioned),
    "badly_scaled": (60, badly_scaled),
    "degenerate_lp": (60, degenerate_lp),
    "dependent_rows": (50, dependent_rows),
    "large_multipliers": (50, large_multipliers),
    "sizes": (40, sizes),
    "fixed_entries": (50, fixed_entries),
    "second_order": (50, second_order),
    "friction": (50, friction),
    "primal_infeasible": (30, primal_infeasible),
    "dual_infeasible": (30, dual_infeasible),
    "qpsolvers": (len(_QPSOLVERS_PROBLEMS), from_qpsolvers),
}
"""Family name -> (number of members, builder of member ``k``), in suite order."""


def _order() -> list[tuple[str, int]]:
    """``(family, member)`` in suite order: the families interleaved."""
    longest = max(count for count, _ in FAMILIES.values())
    return [(name, k) for k in range(longest) for name, (count, _) in FAMILIES.items()
            if k < count]


def build(family: str, member: int) -> SuiteProblem:
    """Member ``member`` of ``family``, regenerated from its own seed."""
    count, builder = FAMILIES[family]
    if not 0 <= member < count:
        raise ValueError(f"{family} has members 0..{count - 1}, got {member}")
    number = list(FAMILIES).index(family)
    problem, expected = builder(np.random.default_rng((SEED, number, member)), member, count)
    return SuiteProblem(_order().index((family, member)), family, member, expected, problem)


def suite(count: int | None = None) -> list[SuiteProblem]:
    """The first ``count`` problems of the suite (all of them by default)."""
    order = _order()[:count]
    return [build(family, member) for family, member in order]
