"""Check a returned point from the problem data alone: :func:`verify_solution`.

Nothing here calls into fccqp beyond reading the cone specs' public fields, so a bug in
the solver's own residuals, scaling or cone code cannot hide itself. What is checked
depends on the status, following the guarantees of docs/formulation.md:

- ``SOLVED``: primal residual (``|Ax - b|``, the distance of ``x`` to the box, the exact
  Euclidean distance of each cone block to its cone), dual residual
  ``||Px + q + A'y + z||``, the multiplier conditions (``z_i <= 0`` only where a lower
  bound exists, ``>= 0`` only where an upper bound exists, ``0`` on free entries,
  ``-z_block`` in the dual cone), complementarity and the duality gap
  ``|x'Px + q'x + b'y + sigma_C(z)|``; the claimed ``dual_res`` must not understate the
  recomputed one, nor ``prim_res`` the recomputed box and cone violation;
- ``SOLVED_INACCURATE``: the same within 10x the tolerances;
- ``MAX_ITER_REACHED``, ``TIME_LIMIT_REACHED``: ``A x = b`` to factorization accuracy;
- ``PRIMAL_INFEASIBLE``: the certificate ``(dy, dz)`` has ``A'dy + dz ~ 0`` and
  ``b'dy + sigma_C(dz) < 0``, with ``sigma_C(dz)`` finite (``dz`` of the right sign on
  the box, ``-dz_block`` in the dual cones), the separation beyond rounding and beyond
  what the residual of ``A'dy + dz ~ 0`` could explain (see below);
- ``DUAL_INFEASIBLE``: the certificate ``dx`` has ``P dx ~ 0``, ``A dx ~ 0``,
  ``q'dx < 0`` and lies in the recession cone of the box and cones;
- ``NUMERICAL_ERROR``: nothing is promised.

Tolerances are ``eps_abs + eps_rel * scale`` with scales taken from the data and the
primal point (``||b||``, ``|A||x|``, ``||q||``, ``||Px||``, ``|q'x|``, ``|x'Px|``),
never from the multipliers: an iterate with multipliers of 1e8 must not make its own
residuals look small. Certificate conditions are relative to the size of their own
terms (the dual certificate's ``P dx ~ 0`` and ``A dx ~ 0`` to each row's norm times
``||dx||``, columns balanced: along a ray in a coordinate-aligned null space of ``P``
the ray adds nothing to the terms of ``P dx``, which then measured the unconverged
rest against itself), so they are invariant to scaling the certificate, the rows of
``A`` or the objective.

The primal certificate's separation. By Farkas, ``(dy, dz)`` proves that no ``x`` has
``A x = b`` and ``x`` in C when ``A'dy + dz = 0`` and ``b'dy + sigma_C(dz) < 0``; with a
residual ``res = A'dy + dz``, any feasible ``x`` has ``b'dy + sigma_C(dz) >= res'x``, so
the separation must be large against what the residual can explain. It is judged by
``delta = (b'dy + sigma_C(dz)) / size`` (``size`` the magnitude of its terms) against
``rho = ||res|| / ||terms of res||``: ``delta < -max(separation, dominance * rho)``. A
feasible ``x`` would need products with the certificate ``dominance`` times larger
than ``b``'s to explain such a separation; ``separation`` (1e-10) stays far above the
rounding of the sum (``1e-16`` of its terms, times its cancellation). On the box
the bound is explicit: ``res'x >= -sigma_box(-res)``, which the separation must also
beat; with columns scaled over 1e16 the residual's relative size says nothing of its
products with the bounds (a feasible problem's certificate had ``rho = 3e-9`` and
``delta = -0.05``, and its residual reached 23 times its separation in the box). A fixed margin
in ``eps_prim_inf`` (this checker asked ``delta < -10 eps_prim_inf`` before) is not a
property of a proof: none of the anchors asks it (OSQP: ``u'dy+ + l'dy- < 0``; SCS:
``b'y < -1e-9`` and ``||A'y|| <= 1e-7 |b'y|``; Clarabel: ``b'z < -1e-8`` and ``||A'z||
<= 1e-8 |b'z|``), and it rejected every certificate of problems that are infeasible by
less: a duplicated row whose right-hand side is off by ``1.5e-6`` of its terms allows
no certificate with ``|delta|`` above ``1.5e-6`` (Clarabel: infeasible), while no other
status could pass either (``A x = b`` has no solution). The dominance test is what the
margin stood in for: a feasible problem with nearly dependent rows once passed the
solver's old test with ``rho = 9e-7`` and ``delta = -1.1e-6``, which ``dominance = 10``
rejects.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

import fccqp
from fccqp import FrictionCone, SecondOrderCone, Status

Z_AXIS = np.array([0.0, 0.0, 1.0])


@dataclass(frozen=True)
class Problem:
    """``min 1/2 x'Px + q'x  s.t.  A x = b, lb <= x <= ub, x[block] in cone``, dense.

    Build it with :meth:`of`, which accepts what ``fccqp.solve`` accepts (``None`` for
    absent parts, lists, ``scipy.sparse``); :meth:`args` gives the arguments back for
    ``fccqp.solve(*problem.args())``.
    """

    P: np.ndarray
    q: np.ndarray
    A: np.ndarray
    b: np.ndarray
    lb: np.ndarray
    ub: np.ndarray
    cones: tuple = ()

    @classmethod
    def of(cls, P, q, A=None, b=None, lb=None, ub=None, cones=()) -> Problem:
        """The problem as dense float arrays (absent parts as empty or infinite ones)."""
        dense = lambda M: np.asarray(M.toarray() if sp.issparse(M) else M, float)  # noqa: E731
        P = dense(P)
        n = P.shape[0]
        A = np.zeros((0, n)) if A is None else dense(A).reshape(-1, n)
        b = np.zeros(0) if b is None else np.asarray(b, float).reshape(-1)
        lb = np.full(n, -np.inf) if lb is None else np.asarray(lb, float).reshape(-1)
        ub = np.full(n, np.inf) if ub is None else np.asarray(ub, float).reshape(-1)
        if isinstance(cones, (FrictionCone, SecondOrderCone)):
            cones = (cones,)
        return cls(P, np.asarray(q, float).reshape(-1), A, b, lb, ub, tuple(cones))

    def args(self) -> tuple:
        """``(P, q, A, b, lb, ub, cones)`` for ``fccqp.solve``."""
        return self.P, self.q, self.A, self.b, self.lb, self.ub, self.cones

    @property
    def n(self) -> int:
        """Number of variables."""
        return self.q.shape[0]

    def blocks(self) -> list[tuple[slice, float, np.ndarray]]:
        """Each cone as ``(block, mu, normal)``; a second-order cone is ``mu = 1`` about
        its first entry, written in the same form as a friction cone."""
        out = []
        for cone in self.cones:
            if isinstance(cone, FrictionCone):
                normal = Z_AXIS if cone.normal is None else np.asarray(cone.normal, float)
                out.append((slice(cone.start, cone.start + 3), float(cone.mu), normal))
            else:
                axis = np.zeros(cone.dim)
                axis[0] = 1.0
                out.append((slice(cone.start, cone.start + cone.dim), 1.0, axis))
        return out

    def in_cone(self) -> np.ndarray:
        """Mask of the entries that belong to some cone block."""
        mask = np.zeros(self.n, dtype=bool)
        for block, _, _ in self.blocks():
            mask[block] = True
        return mask


@dataclass(frozen=True)
class Tolerances:
    """What :func:`verify_solution` accepts.

    ``eps_abs``, ``eps_rel`` are the solver's; a check passes within ``factor`` times
    ``eps_abs + eps_rel * scale`` (the solver measures the same quantities, but its
    scales may differ by small factors). ``certificate`` bounds the relative
    violations of an infeasibility certificate (and the relative margin of the dual
    one's ``q'dx < 0``); ``separation`` and ``dominance`` the primal certificate's
    separation (see the module docstring); ``equality`` the relative error of
    ``A x = b`` that "factorization accuracy" allows.
    """

    eps_abs: float = 1e-5
    eps_rel: float = 1e-5
    factor: float = 10.0
    certificate: float = 1e-5
    separation: float = 1e-10
    dominance: float = 10.0
    equality: float = 1e-9

    @classmethod
    def of(cls, settings: fccqp.Settings | None = None, **overrides: float) -> Tolerances:
        """The tolerances a solve with these settings (and overrides) must meet."""
        s = (settings or fccqp.Settings()).replace(
            **{k: v for k, v in overrides.items() if k in fccqp.Settings.__dataclass_fields__}
        )
        certificate = 10 * max(s.eps_prim_inf, s.eps_dual_inf)
        own = {k: v for k, v in overrides.items()
               if k in ("factor", "equality", "certificate", "separation", "dominance")}
        return cls(**{"eps_abs": s.eps_abs, "eps_rel": s.eps_rel,
                      "certificate": certificate, **own})

    def bound(self, scale: float, looser: float = 1.0) -> float:
        """``factor * looser * (eps_abs + eps_rel * scale)``."""
        return self.factor * looser * (self.eps_abs + self.eps_rel * scale)


@dataclass
class Report:
    """Each check as ``name -> (value, bound)``; it passes when ``value <= bound``."""

    status: Status
    checks: dict[str, tuple[float, float]] = field(default_factory=dict)

    def add(self, name: str, value: float, bound: float) -> None:
        """Record one check (a NaN value fails)."""
        self.checks[name] = (float(value), float(bound))

    @property
    def failures(self) -> dict[str, tuple[float, float]]:
        """The checks that do not hold."""
        return {k: (v, b) for k, (v, b) in self.checks.items() if not v <= b}

    @property
    def passed(self) -> bool:
        """True when every check holds."""
        return not self.failures

    def __str__(self) -> str:
        lines = [f"status {self.status}"]
        for name, (value, bound) in self.checks.items():
            mark = "ok  " if value <= bound else "FAIL"
            lines.append(f"  {mark} {name}: {value:.3g} <= {bound:.3g}")
        return "\n".join(lines)


def _inf(v: np.ndarray) -> float:
    return float(np.max(np.abs(v), initial=0.0))


def cone_distance(block: np.ndarray, mu: float, normal: np.ndarray) -> float:
    """Euclidean distance of ``block`` to ``{f : ||f - (n'f) n|| <= mu n'f}``.

    In the plane of the normal and the tangential part the cone is the angle
    ``t <= mu s``: a point inside is at distance 0, a point in the polar cone
    (``mu t <= -s``) projects onto the apex, any other onto the boundary ray
    ``(1, mu) / sqrt(1 + mu^2)``. With ``mu = 1`` about the first axis this is the
    second-order cone ``||v|| <= t``.
    """
    s = float(normal @ block)
    t = float(np.linalg.norm(block - s * normal))
    if t <= mu * s:
        return 0.0
    if mu * t <= -s:
        return float(np.linalg.norm(block))
    return (t - mu * s) / np.sqrt(1.0 + mu * mu)


def dual_cone_distance(block: np.ndarray, mu: float, normal: np.ndarray) -> float:
    """Distance of ``block`` to the dual of the cone (the friction cone with ``1/mu``)."""
    return cone_distance(block, 1.0 / mu, normal)


def primal_violations(problem: Problem, x: np.ndarray) -> dict[str, float]:
    """``|Ax - b|``, the box violation and the largest cone distance, infinity norms."""
    box = np.maximum(problem.lb - x, 0) + np.maximum(x - problem.ub, 0)
    cone = [cone_distance(x[blk], mu, nrm) for blk, mu, nrm in problem.blocks()]
    return {
        "equality": _inf(problem.A @ x - problem.b),
        "box": _inf(box),
        "cone": max(cone, default=0.0),
    }


def equality_bound(problem: Problem, x: np.ndarray, tolerances: Tolerances) -> float:
    """Factorization accuracy of ``A x = b``: relative to the terms of ``A x`` and ``b``."""
    terms = np.abs(problem.A) @ np.abs(x) if problem.A.size else np.zeros(0)
    return tolerances.equality * max(1.0, _inf(problem.b), _inf(terms))


def _box_support(z: np.ndarray, lb: np.ndarray, ub: np.ndarray) -> tuple[float, np.ndarray]:
    """``sigma_box(z)`` over the finite sides, and the part of ``z`` with no side:
    ``z_i > 0`` where ``ub_i = inf``, ``z_i < 0`` where ``lb_i = -inf``."""
    up, down = np.maximum(z, 0), np.minimum(z, 0)
    has_ub, has_lb = np.isfinite(ub), np.isfinite(lb)
    support = float(up[has_ub] @ ub[has_ub] + down[has_lb] @ lb[has_lb])
    unbounded_side = np.where(has_ub, 0, up) - np.where(has_lb, 0, down)
    return support, unbounded_side


def _multiplier_conditions(problem: Problem, z: np.ndarray) -> tuple[float, float, float]:
    """``sigma_C(z)`` over its finite part, the box sign violation (multipliers on a
    side with no bound, or on free entries) and the largest dual-cone distance."""
    in_cone = problem.in_cone()
    support, unbounded_side = _box_support(z, problem.lb, problem.ub)
    sign = _inf(np.where(in_cone, 0, unbounded_side))
    dual = [dual_cone_distance(-z[blk], mu, nrm) for blk, mu, nrm in problem.blocks()]
    return support, sign, max(dual, default=0.0)


def _box_complementarity(problem: Problem, x: np.ndarray, z: np.ndarray) -> float:
    """Largest ``|z_i| * (distance of x_i to the bound on z_i's side)`` over the box."""
    to_ub = np.abs(np.where(np.isfinite(problem.ub), problem.ub, x) - x)
    to_lb = np.abs(x - np.where(np.isfinite(problem.lb), problem.lb, x))
    gap_up = np.where(z > 0, z * to_ub, 0)
    gap_down = np.where(z < 0, -z * to_lb, 0)
    values = np.where(problem.in_cone(), 0, np.maximum(gap_up, gap_down))
    return _inf(values)


def _check_point(problem: Problem, result: fccqp.Result, tol: Tolerances, report: Report,
                 looser: float) -> None:
    P, q, A, b = problem.P, problem.q, problem.A, problem.b
    x, y, z = result.x, result.y, result.z
    finite = all(v is not None and np.all(np.isfinite(v)) for v in (x, y, z))
    report.add("finite point", 0.0 if finite else 1.0, 0.0)
    if not finite:
        return
    Px, Ax = P @ x, A @ x
    primal = primal_violations(problem, x)
    primal_scale = max(1.0, _inf(b), _inf(Ax))
    report.add("equality", primal["equality"], equality_bound(problem, x, tol))
    report.add("box", primal["box"], tol.bound(max(1.0, _inf(x)), looser))
    # the tolerance is on the entrywise (infinity-norm) distance, which the Euclidean
    # distance of a block of d entries exceeds by at most sqrt(d)
    widest = max((blk.stop - blk.start for blk, _, _ in problem.blocks()), default=1)
    report.add("cone", primal["cone"] / np.sqrt(widest), tol.bound(max(1.0, _inf(x)), looser))

    dual_scale = max(1.0, _inf(q), _inf(Px))
    stationarity = _inf(Px + q + A.T @ y + z)
    report.add("dual residual", stationarity, tol.bound(dual_scale, looser))
    support, sign, dual_cone = _multiplier_conditions(problem, z)
    report.add("box multiplier sign", sign, tol.bound(dual_scale, looser))
    report.add("dual cone", dual_cone, tol.bound(dual_scale, looser))

    xPx, qx = float(x @ Px), float(q @ x)
    gap_scale = max(1.0, abs(xPx), abs(qx))
    gap = abs(xPx + qx + float(b @ y) + support)
    report.add("duality gap", gap, tol.bound(gap_scale, looser))
    cone_compl = [abs(float(x[blk] @ z[blk])) for blk, _, _ in problem.blocks()]
    complementarity = max(_box_complementarity(problem, x, z), max(cone_compl, default=0.0))
    report.add("complementarity", complementarity, tol.bound(gap_scale, looser))

    # The claims must not understate the truth (issue 11, item 1): dual_res is the
    # same quantity; prim_res bounds the entrywise box and cone violation.
    slack = 1e-9 * dual_scale
    # as for the primal claim below: A'y is computed to eps |A|'|y| (|A|'|y| of 1.2e9
    # beside |q| of 15 in a fuzz case: claimed 6.2e-8, recomputed here 8.6e-8, in
    # extended precision 4.1e-8)
    products = np.abs(A).T @ np.abs(y) if A.size else np.zeros(0)
    dual_rounding = 1e-12 * max(_inf(products), _inf(np.abs(P) @ np.abs(x)))
    report.add("claimed dual_res", stationarity,
               result.dual_res * (1 + 1e-6) + slack + dual_rounding)
    # a block's Euclidean distance exceeds its entrywise one by at most sqrt(its size)
    entrywise = max((cone_distance(x[blk], mu, nrm) / np.sqrt(blk.stop - blk.start)
                     for blk, mu, nrm in problem.blocks()), default=0.0)
    violation = max(primal["equality"], primal["box"], entrywise)
    # A x itself is computed to eps |A||x|, and a cone distance at x to eps |x|: a claim
    # may differ from this recomputation by that much (|A||x| = 3e8 against |b| = 4 in
    # a random problem; polished blocks of size 1e8 on a cone's boundary, 3e-9 from it
    # recomputed, 0 claimed)
    rounding = 1e-12 * max(_inf(np.abs(A) @ np.abs(x)), _inf(x))
    report.add("claimed prim_res", violation,
               result.prim_res * (1 + 1e-6) + 1e-9 * primal_scale + rounding)
    # the gap's sums are computed to eps times the sum of their terms' magnitudes
    # (|q|'|x| of 1e10 against q'x of -117 with P = 0 in a fuzz case: claimed 3.3e-7,
    # recomputed here 1.6e-6, exactly 9.8e-7), as A'y and A x above
    finite_bounds = np.where(z > 0, np.where(np.isfinite(problem.ub), problem.ub, 0),
                             np.where(np.isfinite(problem.lb), problem.lb, 0))
    gap_terms = (float(np.abs(x) @ (np.abs(P) @ np.abs(x))) + float(np.abs(q) @ np.abs(x))
                 + float(np.abs(b) @ np.abs(y)) + float(np.abs(finite_bounds) @ np.abs(z)))
    if np.isfinite(result.gap):
        report.add("claimed gap", gap,
                   result.gap * (1 + 1e-6) + 1e-9 * gap_scale + 1e-12 * gap_terms)


def _check_primal_certificate(problem: Problem, result: fccqp.Result, tol: Tolerances,
                              report: Report) -> None:
    m, cert = problem.b.shape[0], result.certificate
    dy, dz = cert[:m], cert[m:]
    # "~ 0" relative to the terms that must cancel (|A|'|dy| + |dz|), as formulation.md
    # says; with no terms at all (dy only on rows of A with no entry, dz = 0) every
    # residual below is exactly 0, and b'dy < 0 proves alone (a row 0 = b_i)
    report.add("certificate size", 0.0 if _inf(cert) > 0 else 1.0, 0.0)
    if not _inf(cert) > 0:
        return
    terms = _inf(np.abs(problem.A).T @ np.abs(dy) + np.abs(dz)) or 1.0
    residual = _inf(problem.A.T @ dy + dz) / terms
    report.add("A'dy + dz ~ 0 (relative)", residual, tol.certificate)
    support, sign, dual_cone = _multiplier_conditions(problem, dz)
    report.add("dz sign on the box (relative)", sign / terms, tol.certificate)
    report.add("-dz in the dual cones (relative)", dual_cone / terms, tol.certificate)
    by = float(problem.b @ dy)
    size = max(abs(by), abs(support), np.abs(problem.b) @ np.abs(dy))
    # b'dy + sigma_C(dz) must be negative beyond rounding of its own terms and beyond
    # what the residual explains (the module docstring)
    report.add("b'dy + sigma(dz) < 0 (relative)", (by + support) / max(size, 1e-300),
               -max(tol.separation, tol.dominance * residual))
    # and beyond what the residual reaches in the box: every feasible x has b'dy +
    # sigma_C(dz) >= res'x, at least -sigma_box(-res) over the box's finite sides
    reach, _ = _box_support(-(problem.A.T @ dy + dz), problem.lb, problem.ub)
    report.add("b'dy + sigma(dz) < -sigma_box(-res) (relative)",
               (by + support + reach) / max(size, 1e-300), -tol.separation)


def _row_relative(M: np.ndarray, dx: np.ndarray) -> float:
    """``max_i |M_i dx| / ||M_i||_1`` (a zero row counts 0) for ``||dx||_inf = 1``; the
    callers balance the columns first (``x = D u`` with ``D_j = 1 / sqrt(max_i
    |M_ij|)``), since in the user's units a row whose norm comes from large-scale
    variables hides curvature on small-scale ones."""
    norms = np.abs(M).sum(axis=1)
    products = np.abs(M @ dx)
    return float(np.max(np.where(norms > 0, products / np.where(norms > 0, norms, 1.0), 0.0),
                        initial=0.0))


def _check_dual_certificate(problem: Problem, result: fccqp.Result, tol: Tolerances,
                            report: Report) -> None:
    dx = result.certificate
    size = _inf(dx)
    report.add("certificate size", 0.0 if size > 0 else 1.0, 0.0)
    if not size > 0:
        return
    dx = dx / size
    # "~ 0" row by row against the row's norm times ||dx||, with the columns balanced
    # (as formulation.md says); "< 0" relative to the terms of the sum. The balance
    # reads A with each row at unit size (A dx = 0 is the same claim for any row
    # scaling): rows of 1e-51..1e-119 had let the columns they alone touch be clipped
    # to the floor below, shrinking a ray along them 1e4 times against the bounded
    # remnants elsewhere (extreme_data:100228)
    rows = np.abs(problem.A).max(axis=1, initial=0.0)
    A_rows = problem.A / np.where(rows > 0, rows, 1.0)[:, None]
    columns = np.maximum(np.abs(problem.P).max(axis=0, initial=0.0),
                         np.abs(A_rows).max(axis=0, initial=0.0))
    # a column of norm 1e-118 is not scaled up 1e59 (it would crush the rest of dx),
    # as equilibrations bound their factors
    D = 1.0 / np.sqrt(np.clip(np.where(columns > 0, columns, 1.0), 1e-8, 1e8))
    balanced = dx / D
    balanced /= _inf(balanced)
    report.add("P dx ~ 0 (relative)", _row_relative(D[:, None] * problem.P * D, balanced),
               tol.certificate)
    report.add("A dx ~ 0 (relative)", _row_relative(problem.A * D, balanced), tol.certificate)
    report.add("q'dx < 0 (relative)",
               float(problem.q @ dx) / max(float(np.abs(problem.q) @ np.abs(dx)), 1e-300),
               -tol.certificate)
    recession = np.where(np.isfinite(problem.lb), np.maximum(-dx, 0), 0) + np.where(
        np.isfinite(problem.ub), np.maximum(dx, 0), 0)
    report.add("dx in the box's recession cone", _inf(recession), tol.certificate)
    cone = [cone_distance(dx[blk], mu, nrm) for blk, mu, nrm in problem.blocks()]
    report.add("dx in the cones", max(cone, default=0.0), tol.certificate)


def check_solution(problem: Problem, result: fccqp.Result,
                   tolerances: Tolerances | None = None) -> Report:
    """Recompute what ``result.status`` promises about ``result`` (see the module
    docstring) and return every check; :func:`verify_solution` asserts them."""
    tol = tolerances or Tolerances()
    report = Report(result.status)
    status = result.status
    if status is Status.SOLVED:
        _check_point(problem, result, tol, report, 1.0)
    elif status is Status.SOLVED_INACCURATE:
        _check_point(problem, result, tol, report, 10.0)
    elif status in (Status.MAX_ITER_REACHED, Status.TIME_LIMIT_REACHED):
        x = result.x
        value = _inf(problem.A @ x - problem.b) if np.all(np.isfinite(x)) else np.inf
        report.add("equality", value, equality_bound(problem, x, tol))
    elif status.is_infeasible():
        report.add("certificate present", 0.0 if result.certificate is not None else 1.0, 0.0)
        if result.certificate is not None:
            check = (_check_primal_certificate if status is Status.PRIMAL_INFEASIBLE
                     else _check_dual_certificate)
            check(problem, result, tol, report)
    return report


def from_qpsolvers(problem, solution) -> tuple[Problem, fccqp.Result]:
    """A qpsolvers problem and fccqp's ``Solution`` of it, in fccqp's slack form.

    Re-derived here from qpsolvers' definitions, not taken from the backend: with
    ``s = G x`` the problem is ``[A 0; G -I] [x; s] = [b; 0]``, ``[lb; -inf] <= [x; s]
    <= [ub; h]``, and qpsolvers' duals give ``y_ext = [y; z]``, ``z_ext = [z_box; z]``
    (stationarity in ``s`` reads ``-y_G + z_s = 0``). The ``Result`` carries the
    status and claimed residuals from ``solution.extras``.
    """
    P, q, G, h, A, b, lb, ub = (None if v is None else
                                np.asarray(v.toarray() if sp.issparse(v) else v, float)
                                for v in problem.unpack())
    n = q.shape[0]
    G = np.zeros((0, n)) if G is None else G.reshape(-1, n)
    h = np.zeros(0) if h is None else h.reshape(-1)
    A = np.zeros((0, n)) if A is None else A.reshape(-1, n)
    b = np.zeros(0) if b is None else b.reshape(-1)
    k = G.shape[0]
    P_ext = np.zeros((n + k, n + k))
    P_ext[:n, :n] = P
    A_ext = np.block([[A, np.zeros((A.shape[0], k))], [G, -np.eye(k)]])
    lb_ext = np.concatenate([np.full(n, -np.inf) if lb is None else lb, np.full(k, -np.inf)])
    ub_ext = np.concatenate([np.full(n, np.inf) if ub is None else ub, h])
    ext = Problem.of(P_ext, np.concatenate([q, np.zeros(k)]), A_ext,
                     np.concatenate([b, np.zeros(k)]), lb_ext, ub_ext)
    extras = solution.extras
    present = solution.x is not None
    z_box = solution.z_box if present and solution.z_box.size else np.zeros(n)
    result = fccqp.Result(
        x=np.concatenate([solution.x, G @ solution.x]) if present else np.zeros(n + k),
        y=np.concatenate([solution.y, solution.z]) if present else np.zeros(0),
        z=np.concatenate([z_box, solution.z]) if present else np.zeros(0),
        status=extras["status"], obj=solution.obj, iterations=extras["iterations"],
        # no residual claim: qpsolvers' z stands for both the slack rows' multiplier and
        # the slack bound's, which agree only at the optimum (see the docstring)
        prim_res=np.inf, dual_res=np.inf,
        setup_time=extras["setup_time"], solve_time=extras["solve_time"], rho=extras["rho"],
        factorizations=extras["factorizations"], certificate=extras.get("certificate"),
    )
    return ext, result


def verify_solution(problem: Problem | Sequence, result: fccqp.Result,
                    tolerances: Tolerances | None = None) -> Report:
    """Assert that ``result`` keeps the promises of its status for ``problem``.

    ``problem`` is a :class:`Problem` or the tuple ``(P, q, A, b, lb, ub, cones)``.
    Raises ``AssertionError`` listing every check; returns the :class:`Report`.
    """
    if not isinstance(problem, Problem):
        problem = Problem.of(*problem)
    report = check_solution(problem, result, tolerances)
    assert report.passed, str(report)
    return report
