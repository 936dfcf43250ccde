"""Residuals, the termination test and the infeasibility certificates of the sparse path.

The same quantities as the dense core's :mod:`fccqp.termination` and
:mod:`fccqp.certificates`, vectorized over ``scipy.sparse`` data (their docstrings
give the reasons for each choice): the residuals of an ADMM iterate in the user's
units, with scales from the data and the primal point only; the residuals of a
returned point on the user's own data (:func:`user_residuals`), on which the status
is settled; and the three certificates, each "approximately zero" judged against the
size of the terms that cancel.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fccqp.sparse_problem import Scaled, SparseData


@dataclass
class Residuals:
    """Residuals of a point in the user's units, the scales of their relative
    tolerances, and the scaled values that rho adaptation balances (the fields of
    :mod:`fccqp.termination`'s ``Residuals``)."""

    prim_eq: float = 0.0
    prim_eq_scale: float = 0.0
    prim_set: float = 0.0
    prim_set_scale: float = 0.0
    dual: float = 0.0
    dual_scale: float = 0.0
    gap: float = 0.0
    gap_scale: float = 0.0
    prim_s: float = 0.0
    prim_scale_s: float = 0.0
    dual_s: float = 0.0
    dual_scale_s: float = 0.0
    objective: float = 0.0
    finite: bool = True

    @property
    def prim(self) -> float:
        """The reported primal residual: the larger of its two parts."""
        return max(self.prim_eq, self.prim_set)

    @property
    def prim_scale(self) -> float:
        """The larger of the primal parts' scales."""
        return max(self.prim_eq_scale, self.prim_set_scale)

    def within(self, eps_abs: float, eps_rel: float, factor: float = 1.0) -> bool:
        """The termination test with tolerances multiplied by ``factor``: both primal
        parts, the dual residual and the gap each within ``eps_abs + eps_rel * scale``."""
        return bool(
            self.finite
            and self.prim_eq <= factor * (eps_abs + eps_rel * self.prim_eq_scale)
            and self.prim_set <= factor * (eps_abs + eps_rel * self.prim_set_scale)
            and self.dual <= factor * (eps_abs + eps_rel * self.dual_scale)
            and self.gap <= factor * (eps_abs + eps_rel * self.gap_scale))


def dot(a: np.ndarray, b: np.ndarray) -> float:
    """``a'b`` without BLAS: numpy's BLAS may run a long dot product multithreaded, and
    on a loaded machine a multithreaded call waits for its workers (45000 entries, 2
    busy cores: 1.5 ms through ``@`` against 0.07 ms through ``einsum``)."""
    return float(np.einsum("i,i->", a, b))


def _max(v: np.ndarray) -> float:
    return float(np.max(v, initial=0.0))


def _capped(size: np.ndarray, span: np.ndarray) -> np.ndarray:
    """``size`` capped by a positive ``span`` (see :mod:`fccqp.termination`)."""
    return np.where(span > 0.0, np.minimum(size, span), size)


def _box_support(y: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> tuple[float, float]:
    """``sigma_box(y)`` over the finite sides and the sum of the magnitudes of its terms
    (infinite sides skipped: ADMM's multiplier is exactly 0 there)."""
    up, down = (y > 0.0) & np.isfinite(hi), (y < 0.0) & np.isfinite(lo)
    values = np.zeros_like(y)
    values[up] = hi[up] * y[up]
    values[down] = lo[down] * y[down]
    return float(values.sum()), float(np.abs(values).sum())


def iterate_residuals(p: Scaled, x: np.ndarray, nu: np.ndarray, z: np.ndarray,
                      y: np.ndarray) -> Residuals:
    """Residuals of the scaled ADMM iterate ``(x, nu, z, y)`` (slack ``z`` in ``C``), in
    the user's units: row ``i`` divided by ``E_i``, entry ``i`` of ``x`` multiplied by
    ``D_i`` and of the gradient divided by ``c D_i``."""
    S, c = p.constrained, p.c
    r = Residuals()
    Ax, ATnu, Px = p.A @ x, p.AT @ nu, p.P @ x
    eq, eq_size = np.abs(Ax - p.b), np.maximum(np.abs(Ax), np.abs(p.b))
    xs = x[S]
    gap_set, set_size = np.abs(xs - z), np.maximum(np.abs(xs), np.abs(z))
    r.prim_eq, r.prim_eq_scale = _max(eq / p.E), _max(eq_size / p.E)
    r.prim_set, r.prim_set_scale = _max(gap_set * p.D[S]), _max(set_size * p.D[S])
    r.prim_s = max(_max(eq), _max(gap_set))
    r.prim_scale_s = max(_max(_capped(eq_size, p.span)), _max(_capped(set_size, p.hi - p.lo)))
    unit = 1.0 / (c * p.D)
    size = np.maximum(np.abs(Px), np.abs(p.q))
    r.dual_scale = _max(size * unit)
    r.dual_scale_s = max(_max(np.maximum(size, np.abs(ATnu))), _max(np.abs(y)))
    xPx, qx = dot(x, Px), dot(p.q, x)
    grad = Px + p.q + ATnu
    grad[S] += y
    r.dual, r.dual_s = _max(np.abs(grad) * unit), _max(np.abs(grad))
    support, terms = _box_support(y, p.lo, p.hi)
    bnu = p.b * nu
    r.gap = abs(xPx + qx + float(bnu.sum()) + support) / c
    r.gap_scale = max(abs(xPx), abs(qx), float(np.abs(bnu).sum()) + terms) / c
    r.finite = bool(np.isfinite(r.prim_s + r.prim_eq + r.prim_set + r.dual + r.dual_s
                                + r.gap + r.gap_scale + float(np.abs(y).sum())))
    return r


def user_residuals(data: SparseData, p: Scaled, x: np.ndarray, y: np.ndarray,
                   z: np.ndarray) -> Residuals:
    """Residuals of a returned ``(x, y, z)`` on the user's data (as
    ``fccqp.acceptance.user_residuals``): ``||A x - b||``, the distance of ``x_S``
    to the box and the exact cones, ``||P x + q + A'y + z||`` and the gap with
    ``sigma_C(z)``; ``p`` provides only the cone blocks."""
    S = data.constrained
    r = Residuals()
    Ax, ATy, Px = data.A @ x, data.A.T @ y, data.P @ x
    r.prim_eq = _max(np.abs(Ax - data.b))
    r.prim_eq_scale = _max(np.maximum(np.abs(Ax), np.abs(data.b)))
    xs = x[S]
    lb, ub = data.lb[S], data.ub[S]
    projected = np.minimum(np.maximum(xs, lb), ub)
    cone_part = p.project_cones(xs)
    projected[p.in_cone] = cone_part[p.in_cone]
    r.prim_set, r.prim_set_scale = _max(np.abs(xs - projected)), _max(np.abs(xs))
    support, terms = _box_support(z[S], lb, ub)
    by = data.b * y
    xPx, qx = dot(x, Px), dot(data.q, x)
    r.dual_scale = _max(np.maximum(np.abs(Px), np.abs(data.q)))
    r.dual = _max(np.abs(Px + data.q + ATy + z))
    r.objective = 0.5 * xPx + qx
    r.gap = abs(xPx + qx + float(by.sum()) + support)
    r.gap_scale = max(abs(xPx), abs(qx), float(np.abs(by).sum()) + terms)
    r.finite = bool(np.isfinite(r.dual + r.gap + r.prim + float(np.abs(x).sum())
                                + float(np.abs(y).sum()) + float(np.abs(z).sum())))
    return r


def primal_infeasible(p: Scaled, x: np.ndarray, d_nu: np.ndarray, d_y: np.ndarray,
                      eps: float) -> np.ndarray | None:
    """Test ``(d_nu, d_y)``, the last step's multipliers, as a Farkas certificate (see
    :mod:`fccqp.certificates`); return it in the user's units (``(y, z)`` over the rows
    and all ``n`` entries, the common factor ``1/c`` dropped) or None."""
    S, n, m = p.constrained, p.n, p.m
    d_y = d_y.copy()
    polar = d_y - p.project_cones(d_y)
    d_y[p.in_cone] = polar[p.in_cone]
    box = ~p.in_cone
    d_y[box & ~np.isfinite(p.hi) & (d_y > 0.0)] = 0.0
    d_y[box & ~np.isfinite(p.lo) & (d_y < 0.0)] = 0.0
    support, size = _box_support(np.where(box, d_y, 0.0), p.lo, p.hi)
    bnu = p.b * d_nu
    support += float(bnu.sum())
    size += float(np.abs(bnu).sum())
    if not (support < -eps * size) or not np.isfinite(support):
        return None
    lhs = p.AT @ d_nu
    terms = p.abs_AT @ np.abs(d_nu)
    lhs[S] += d_y
    terms[S] += np.abs(d_y)
    lhs_max, terms_max = _max(np.abs(lhs) / p.D), _max(terms / p.D)
    # for every feasible x, b'd_nu + sigma_C(d_y) >= (A'd_nu + d_y)'x: a separation the
    # residual explains at the iterate's own x proves nothing
    explained = float(np.abs(lhs * x).sum())
    if not (lhs_max <= eps * terms_max and support < -explained):
        return None
    certificate = np.zeros(m + n)
    certificate[:m] = d_nu * p.E
    certificate[m + S] = d_y / p.D[S]
    return certificate


def equality_inconsistent(p: Scaled, x: np.ndarray, eps: float) -> np.ndarray | None:
    """Test the residual ``r = b - A x`` of a regularized (least-squares) solve as a
    certificate that ``A x = b`` has no solution: ``A'r ~ 0`` and ``b'r > 0``. Returns
    ``(-E r, 0)`` in the user's units, or None."""
    if p.m == 0:
        return None
    r = p.b - p.A @ x
    br_terms = p.b * r
    br, size = float(br_terms.sum()), float(np.abs(br_terms).sum())
    if not (br > eps * size) or not np.isfinite(br):
        return None
    lhs_max = _max(np.abs(p.AT @ r) / p.D)
    terms_max = _max((p.abs_AT @ np.abs(r)) / p.D)
    if not lhs_max <= eps * terms_max:
        return None
    certificate = np.zeros(p.m + p.n)
    certificate[:p.m] = -r * p.E
    return certificate


def _near_zero(M, abs_M, dx: np.ndarray, unit: np.ndarray, eps: float) -> bool:
    """``M dx ~ 0`` relative to its largest row of terms, row ``i`` divided by
    ``unit[i]`` (the user's units)."""
    lhs_max = _max(np.abs(M @ dx) / unit)
    terms_max = _max((abs_M @ np.abs(dx)) / unit)
    return lhs_max <= eps * terms_max


def dual_infeasible(p: Scaled, dx: np.ndarray, eps: float) -> np.ndarray | None:
    """Test ``dx`` (scaled) as an unbounded direction: ``q'dx < 0``, ``dx_S`` in the
    recession cone of the box and the cones, ``P dx ~ 0``, ``A dx ~ 0``. Returns ``D dx``
    (the user's units) or None."""
    S = p.constrained
    q_terms = p.q * dx
    qdx, size = float(q_terms.sum()), float(np.abs(q_terms).sum())
    norm = _max(np.abs(dx * p.D))
    if not (qdx < -eps * size) or not np.isfinite(qdx) or norm <= 1e-300:
        return None
    tol = eps * norm
    step = dx[S] * p.D[S]
    if np.any(np.isfinite(p.hi) & (step > tol)) or np.any(np.isfinite(p.lo) & (step < -tol)):
        return None
    block = dx[S]
    if np.any(np.abs(block - p.project_cones(block))[p.in_cone] * p.D[S][p.in_cone] > tol):
        return None
    if not _near_zero(p.P, p.abs_P, dx, p.c * p.D, eps):
        return None
    if p.m and not _near_zero(p.A, p.abs_A, dx, p.E, eps):
        return None
    return dx * p.D
