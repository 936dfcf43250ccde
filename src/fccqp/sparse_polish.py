"""Polishing on the sparse path: the exact solution of the QP on ADMM's active set.

The method of the dense core's :mod:`fccqp.polish` (its docstring gives the maths and
the measurements behind each rule), on ``scipy.sparse`` data with ``qdldl``:

1. guess the active set from the scaled slack ``z`` and multiplier ``y`` by Moreau's
   decomposition of ``v = z + y``: a box entry is held at ``lo`` when ``v < lo``, at
   ``hi`` when ``v > hi`` (always when ``lo == hi``); a cone block is held at the apex
   when ``v`` is in the polar cone, on the boundary when ``v`` is in neither the cone
   nor its polar, free when ``v`` is in the cone;
2. solve the equality-constrained QP on it: held entries at their values, ``A x = b``,
   and one tangent plane ``g'x_block = 0`` per boundary block. Its KKT matrix (free
   entries, equality rows, one row per boundary block) gets ``-DELTA`` / ``+DELTA`` on
   its diagonal blocks, which makes it quasi-definite for ``qdldl``; the solution is
   refined against the unregularized matrix;
3. correct the guess from the polished point, at most ``GUESS_PASSES`` guesses: first
   add only what it violates, then, from a point violating nothing, release
   wrong-signed multipliers;
4. Newton (SQP on the active manifold) on a settled guess: re-linearize each boundary
   plane at the new ``x_block``, the Hessian of the Lagrangian carrying ``lam`` times
   the cone function's curvature; chord steps (one correction with the last
   factorization) while the cones' miss shrinks fast.

Whether the result is accepted is decided by the caller on the user's problem
(:func:`multiplier_violation` and the residuals of :mod:`fccqp.sparse_checks`).
``DELTA`` is ``1e-9`` rather than the dense ``1e-12``, for the reason given in
:mod:`fccqp.sparse_kkt` (no pivoting).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from fccqp.cones import FRICTION
from fccqp.projections import project_cone_block
from fccqp.sparse_problem import Scaled
from fccqp.tuning import (
    ACTIVE_TOLERANCE,
    CHORD_RATE,
    GUESS_PASSES,
    MAX_REFINE,
    MISS_FLOOR,
    NEWTON_TOLERANCE,
    POLISH_REFINE_TOLERANCE,
)

DELTA = 1e-9
"""Regularization of both diagonal blocks of the polishing KKT matrix (scaled problem)."""

FREE, LOWER, UPPER, FIXED, APEX, BOUNDARY = range(6)
"""Codes of the active set, one per constrained entry (as in :mod:`fccqp.polish`)."""


@dataclass
class Polished:
    """A polished point of the scaled problem and the guess it solved."""

    x: np.ndarray
    nu: np.ndarray
    y: np.ndarray
    """Multipliers of the constrained entries (scaled problem)."""
    active: np.ndarray
    """The final guess: one code per constrained entry."""
    factorizations: int


def _slope(kind: int, mu: float) -> float:
    return mu if kind == FRICTION else 1.0


def _axis(v: np.ndarray, kind: int, mu: float, normal: np.ndarray) -> tuple[float, float]:
    """``(along, across)``: the block's part along the cone's axis and the norm of the
    rest, so that the cone reads ``across <= slope * along``."""
    if kind == FRICTION:
        along = float(normal @ v)
        return along, float(np.linalg.norm(v - along * normal))
    return float(v[0]), float(np.linalg.norm(v[1:]))


def _plane(v: np.ndarray, kind: int, mu: float, normal: np.ndarray) -> np.ndarray | None:
    """Unit gradient of the cone function at ``v``; None on the axis (no gradient)."""
    along, across = _axis(v, kind, mu, normal)
    if not across > 0.0:
        return None
    slope = _slope(kind, mu)
    unit = 1.0 / np.sqrt(1.0 + slope * slope)
    if kind == FRICTION:
        return ((v - along * normal) / across - slope * normal) * unit
    g = np.empty_like(v)
    g[0] = -unit
    g[1:] = v[1:] / across * unit
    return g


def _curvature(v: np.ndarray, kind: int, mu: float, normal: np.ndarray,
               weight: float) -> np.ndarray:
    """``weight`` times the Hessian of the cone function at ``v``, divided by
    ``sqrt(1 + slope^2)`` (the normalization of the plane); 0 on the axis."""
    d = v.shape[0]
    along, across = _axis(v, kind, mu, normal)
    H = np.zeros((d, d))
    if not across > 0.0:
        return H
    slope = _slope(kind, mu)
    scale = weight / (np.sqrt(1.0 + slope * slope) * across)
    if kind == FRICTION:
        e = (v - along * normal) / across
        return scale * (np.eye(3) - np.outer(normal, normal) - np.outer(e, e))
    w = v[1:] / across
    H[1:, 1:] = scale * (np.eye(d - 1) - np.outer(w, w))
    return H


class _Polish:
    """The state of one polish: the guess, the boundary blocks' planes, curvatures and
    multipliers, the unknowns and the factorization of the current guess."""

    def __init__(self, p: Scaled, x: np.ndarray, nu: np.ndarray, y: np.ndarray) -> None:
        self.p = p
        self.x, self.nu, self.y = x.copy(), nu.copy(), y.copy()
        self.active = np.full(p.s, FREE, dtype=np.int8)
        kind, offset, dim, mu, normal = p.cones
        self.blocks = [(int(kind[k]), int(offset[k]), int(dim[k]), float(mu[k]), normal[k])
                       for k in range(len(kind))]
        self.boundary: list[int] = []   # cone indices of the boundary blocks
        self.lam = np.zeros(0)
        self.g: dict[int, np.ndarray] = {}   # plane of each boundary block
        self.hess: dict[int, np.ndarray] = {}
        self.factorizations = 0
        self.solver = None

    # ------------------------------------------------------------- the guess

    def _entries(self, k: int) -> slice:
        """Block ``k``'s entries of ``x``."""
        _, o, d, _, _ = self.blocks[k]
        start = int(self.p.constrained[o])
        return slice(start, start + d)

    def _linearize(self, k: int, lam: float, v: np.ndarray) -> None:
        """Plane and curvature of boundary block ``k`` at ``v`` (a block on the axis
        keeps its plane and gets no curvature)."""
        kind, _, _, mu, normal = self.blocks[k]
        g = _plane(v, kind, mu, normal)
        if g is not None:
            self.g[k] = g
        self.hess[k] = _curvature(v, kind, mu, normal, lam)

    def _set_boundary(self, entries: list[tuple[int, float, np.ndarray]]) -> None:
        """The boundary blocks ``(cone, lam, linearization point)``, in cone order."""
        self.boundary = [k for k, _, _ in entries]
        self.lam = np.array([lam for _, lam, _ in entries])
        for k, lam, point in entries:
            self._linearize(k, lam, point)

    def guess(self, z: np.ndarray, y: np.ndarray) -> None:
        """The first guess, from the slack ``z`` and the multiplier ``y``."""
        p = self.p
        v = z + y
        box = ~p.in_cone
        code = np.where(v < p.lo, LOWER, np.where(v > p.hi, UPPER, FREE))
        code = np.where(p.lo == p.hi, FIXED, code)
        self.active[box] = code[box]
        boundary = []
        for k, (kind, o, d, mu, normal) in enumerate(self.blocks):
            block = v[o:o + d]
            slope = _slope(kind, mu)
            along, across = _axis(block, kind, mu, normal)
            if across <= slope * along:
                code_k = FREE
            elif slope * across <= -along:
                code_k = APEX
            else:
                code_k = BOUNDARY
                point = np.empty(d)
                project_cone_block(block, kind, mu, normal, point)
                lam = float(y[o:o + d] @ _plane(point, kind, mu, normal))
                boundary.append((k, lam, point))
            self.active[o:o + d] = code_k
        self._set_boundary(boundary)

    def renew(self, adding: bool) -> int:
        """Correct the guess from the polished point (see :mod:`fccqp.polish`'s
        ``_renew``); return the number of constrained entries whose code changed."""
        p = self.p
        before = self.active.copy()
        box = ~p.in_cone
        value = self.x[p.constrained]
        if adding:
            free = box & (before == FREE)
            low = value < p.lo - ACTIVE_TOLERANCE * np.maximum(1.0, np.abs(p.lo))
            high = value > p.hi + ACTIVE_TOLERANCE * np.maximum(1.0, np.abs(p.hi))
            self.active[free & low] = LOWER
            self.active[free & high & ~low] = UPPER
        else:
            wrong = box & (((before == LOWER) & (self.y > 0.0))
                           | ((before == UPPER) & (self.y < 0.0)))
            self.active[wrong] = FREE
        old = dict(zip(self.boundary, self.lam, strict=True))
        boundary = []
        for k, (kind, o, d, mu, normal) in enumerate(self.blocks):
            code = was = int(before[o])
            slope = _slope(kind, mu)
            lam, point = 0.0, None
            if was == BOUNDARY:
                lam = float(old[k])
                if not adding and lam < 0.0:
                    code = FREE
                point = self.x[self._entries(k)].copy()
            elif was == FREE and adding:
                block = self.x[self._entries(k)]
                along, across = _axis(block, kind, mu, normal)
                if across - slope * along > ACTIVE_TOLERANCE * np.linalg.norm(block):
                    code = APEX if slope * across <= -along else BOUNDARY
                    point = np.empty(d)
                    project_cone_block(np.ascontiguousarray(block), kind, mu, normal, point)
            elif was == APEX and not adding:   # kept while y stays in the polar
                block = self.y[o:o + d]
                along, across = _axis(block, kind, mu, normal)
                if slope * across > -along:
                    code = FREE if across <= slope * along else BOUNDARY
                    point = np.empty(d)
                    project_cone_block(np.ascontiguousarray(block), kind, mu, normal, point)
            self.active[o:o + d] = code
            if code == BOUNDARY:
                boundary.append((k, lam, point))
        self._set_boundary(boundary)
        return int(np.count_nonzero(self.active != before))

    # ---------------------------------------------------- the polished system

    def unknowns(self) -> None:
        """Put the held entries at their values and number the free ones."""
        p = self.p
        S, code = p.constrained, self.active
        held = (code == LOWER) | (code == FIXED) | (code == UPPER) | (code == APEX)
        self.x[S[(code == LOWER) | (code == FIXED)]] = p.lo[(code == LOWER) | (code == FIXED)]
        self.x[S[code == UPPER]] = p.hi[code == UPPER]
        self.x[S[code == APEX]] = 0.0
        free = np.ones(p.n, dtype=bool)
        free[S[held]] = False
        self.free = np.flatnonzero(free)
        self.index = np.full(p.n, -1)
        self.index[self.free] = np.arange(self.free.shape[0])

    def _plane_rows(self) -> sp.csc_matrix:
        """One row per boundary block: its plane over the free unknowns."""
        rows, cols, values = [], [], []
        for r, k in enumerate(self.boundary):
            entries = self.index[self._entries(k)]
            rows += [r] * entries.shape[0]
            cols += list(entries)
            values += list(self.g[k])
        return sp.csc_matrix((values, (rows, cols)), shape=(len(self.boundary),
                                                            self.free.shape[0]))

    def factor(self) -> bool:
        """Assemble and factor the regularized KKT matrix of the current guess and
        planes; False when ``qdldl`` meets a zero pivot."""
        import qdldl

        p, F = self.p, self.free
        nf, m, nb = F.shape[0], p.m, len(self.boundary)
        if nf + m + nb == 0:
            self.solver = None
            return True
        H = p.P[F][:, F].tocoo()
        rows, cols, values = [H.row], [H.col], [H.data]
        for k in self.boundary:
            entries = self.index[self._entries(k)]
            block = self.hess[k]
            rows.append(np.repeat(entries, entries.shape[0]))
            cols.append(np.tile(entries, entries.shape[0]))
            values.append(block.reshape(-1))
        rows.append(np.arange(nf))
        cols.append(np.arange(nf))
        values.append(np.full(nf, DELTA))
        hessian = sp.csc_matrix((np.concatenate(values),
                                 (np.concatenate(rows), np.concatenate(cols))), shape=(nf, nf))
        if m + nb:
            constraints = sp.vstack([p.A[:, F], self._plane_rows()], format="csc")
            K = sp.bmat([[sp.triu(hessian), constraints.T],
                         [None, sp.diags(np.full(m + nb, -DELTA))]], format="csc")
        else:
            K = sp.triu(hessian, format="csc")
        self.factorizations += 1
        try:
            self.solver = qdldl.Solver(K, upper=True)
        except RuntimeError:   # a zero pivot
            return False
        return True

    def residual(self) -> tuple[np.ndarray, np.ndarray]:
        """The residual of the current ``(x, nu, lam)`` in the unregularized system,
        curvature included, and the gradient of the Lagrangian without the boundary
        terms (minus the multipliers of the held entries)."""
        p, F = self.p, self.free
        grad = p.P @ self.x + p.q + p.AT @ self.nu
        top = -grad[F]
        planes = np.zeros(len(self.boundary))
        for r, k in enumerate(self.boundary):
            entries = self._entries(k)
            block = self.x[entries]
            top[self.index[entries]] -= self.lam[r] * self.g[k] + self.hess[k] @ block
            planes[r] = -(self.g[k] @ block)
        return np.concatenate([top, p.b - p.A @ self.x, planes]), grad

    def _apply(self, step: np.ndarray, sign: float) -> None:
        nf, m = self.free.shape[0], self.p.m
        self.x[self.free] += sign * step[:nf]
        self.nu += sign * step[nf:nf + m]
        self.lam = self.lam + sign * step[nf + m:]

    def solve(self, scale: float) -> None:
        """Correct ``(x, nu, lam)`` to the solution of the unregularized system, as
        :mod:`fccqp.polish`'s ``_solve``: until the residual is below
        ``POLISH_REFINE_TOLERANCE * scale``, stops halving, or ``MAX_REFINE`` corrections after
        the first; a correction that makes it grow is undone."""
        if self.solver is None:
            return
        last, step = np.inf, None
        for r in range(MAX_REFINE + 2):
            rhs, _ = self.residual()
            norm = float(np.max(np.abs(rhs), initial=0.0))
            if norm > last:
                self._apply(step, -1.0)
                return
            if norm <= POLISH_REFINE_TOLERANCE * scale or norm > 0.5 * last or r == MAX_REFINE + 1:
                return
            last = norm
            step = self.solver.solve(rhs)
            self._apply(step, 1.0)

    def correct_once(self) -> None:
        """One correction with the last factorization (a chord step)."""
        if self.solver is not None:
            self._apply(self.solver.solve(self.residual()[0]), 1.0)

    def relinearize(self) -> tuple[bool, float]:
        """Move each boundary plane and curvature to the current ``x_block``, unless every
        block meets ``NEWTON_TOLERANCE`` already (then False, planes kept); also
        return the largest miss ``|phi| / ||x_block||``."""
        worst, converged = 0.0, True
        for k in self.boundary:
            kind, _, _, mu, normal = self.blocks[k]
            block = self.x[self._entries(k)]
            along, across = _axis(block, kind, mu, normal)
            miss, size = abs(across - _slope(kind, mu) * along), float(np.linalg.norm(block))
            if miss > NEWTON_TOLERANCE * size:
                converged = False
                worst = max(worst, miss / size)
        if converged:
            return False, worst
        for r, k in enumerate(self.boundary):
            self._linearize(k, float(self.lam[r]), self.x[self._entries(k)].copy())
        return True, worst

    def multipliers(self) -> None:
        """``y``: minus the Lagrangian's gradient on held entries, ``lam g(x)`` on
        boundary blocks, 0 on free entries."""
        p = self.p
        _, grad = self.residual()
        held = (self.active != FREE) & (self.active != BOUNDARY)
        self.y = np.where(held, -grad[p.constrained], 0.0)
        for r, k in enumerate(self.boundary):
            kind, o, d, mu, normal = self.blocks[k]
            g = _plane(self.x[self._entries(k)], kind, mu, normal)
            if g is not None:
                self.g[k] = g
            self.y[o:o + d] = self.lam[r] * self.g[k]


def polish(p: Scaled, x: np.ndarray, nu: np.ndarray, z: np.ndarray, y: np.ndarray,
           newton_steps: int) -> Polished | None:
    """Polish the scaled iterate ``(x, nu, z, y)``: guesses, corrections and Newton as
    in :func:`fccqp.polish.polish`. None when a factorization breaks down or the result
    is not finite; otherwise the caller judges the point."""
    w = _Polish(p, x, nu, y)
    scale = max(1.0, float(np.max(np.abs(p.q), initial=0.0)),
                float(np.max(np.abs(p.b), initial=0.0)))
    w.guess(z, y)
    changed = 0
    for guess in range(GUESS_PASSES):
        if guess > 0:
            changed = w.renew(True)
            if changed == 0:
                changed = w.renew(False)
            if changed == 0:
                break
        w.unknowns()
        if not w.factor():
            return None
        w.solve(scale)
        w.multipliers()
    if changed == 0:
        last_miss, refactored = np.inf, False
        for _ in range(newton_steps):
            moved, miss = w.relinearize()
            if not moved or (refactored and miss >= last_miss and miss <= MISS_FLOOR):
                break   # converged, or at the floor that rounding leaves
            refactored = miss > CHORD_RATE * last_miss
            if not refactored:
                w.correct_once()
            elif not w.factor():
                return None
            else:
                w.solve(scale)
            last_miss = miss
        if not refactored:   # refine the last chord step's point
            w.solve(scale)
        w.multipliers()
    if not np.isfinite(w.x.sum() + w.nu.sum() + w.y.sum()):
        return None
    return Polished(w.x, w.nu, w.y, w.active, w.factorizations)


def multiplier_violation(p: Scaled, active: np.ndarray, z: np.ndarray) -> float:
    """How far the user's multipliers ``z`` (one per entry of ``x``) of a polished point
    are from the normal cone its guess needs: the wrong-signed part at held box
    entries, and on held or boundary cone blocks the distance of ``z_block`` to the
    polar cone, ``||P_K(z_block)||`` (the scaling is constant on a block, so the cones
    are the scaled problem's)."""
    zs = z[p.constrained]
    worst = max(float(np.max(zs[active == LOWER], initial=0.0)),
                float(np.max(-zs[active == UPPER], initial=0.0)))
    kind, offset, dim, mu, normal = p.cones
    for k in range(len(kind)):
        o, d = int(offset[k]), int(dim[k])
        if active[o] == FREE:
            continue
        out = np.empty(d)
        project_cone_block(np.ascontiguousarray(zs[o:o + d]), int(kind[k]), float(mu[k]),
                           np.ascontiguousarray(normal[k]), out)
        worst = max(worst, float(np.linalg.norm(out)))
    return worst
