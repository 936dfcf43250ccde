"""Sparse quasi-definite LDL' backend of the x-update, through ``qdldl``.

The x-update solves, for a right-hand side ``(r, b)``,

    [ P + sigma I + R   A' ] [x ]   [r]
    [ A                 0  ] [nu] = [b],      R = diag(rho on constrained entries),

as the dense ``ldl_full`` backend (:mod:`fccqp.ldl`) does: the zero block is replaced
by ``-delta I``, which makes the matrix quasi-definite (``P + sigma I + R`` is positive
definite on a convex problem), so an LDL' factorization exists in any symmetric
order, rank-deficient ``A`` included; ``qdldl`` factors it in its fill-reducing (AMD)
order, without pivoting. Each solve is refined against the unregularized matrix until
``A x = b`` holds to ``REFINE_TOLERANCE`` of its terms in the user's units and the
first block to ``STATIONARITY_TOLERANCE`` of its own; when a
step stops halving that error while still reducing it, the regularization may be what
holds it back: the matrix is factored again, once, with a smaller ``delta`` read from
the contraction (:meth:`SparseKKT._cut_regularization`), and the refinement goes on;
when a step stops halving the error otherwise, ``A x = b`` has no solution and the
regularized (least-squares) solution is returned, refined against the factored matrix
itself, which the equality certificate reads. A factorization that does not solve even
that matrix (its order put a pivot lost to rounding first) is replaced, until the next
factorization, by SuperLU's with partial pivoting (:meth:`SparseKKT._pivot`).

``delta`` is larger than the dense backend's ``1e-13``: without pivoting, a row of
``A`` eliminated before its variables has the pivot ``-delta`` and adds ``A_i'A_i /
delta`` to the rest, so the rounding of the factorization grows like ``1 / delta``.
At ``DELTA = 1e-9`` (scaled problem) refinement still reaches ``1e-13`` in one or two
steps on well-posed rows.

Inertia. By Sylvester's law the signs of the pivots ``d`` are the inertia of the
factored matrix: without ``R``, more than ``m`` negative pivots means that ``P +
sigma I`` has negative curvature on the null space of ``A`` (the QP is not convex).

Contract (as in :mod:`fccqp.kkt`, whose ``SPARSE_LDL`` backend calls it through
:mod:`fccqp.kkt_sparse`): :class:`SparseKKT` is built once per pattern over the
workspace's scaled compressed-column arrays, which it reads without copying;
:meth:`SparseKKT.factor` assembles the KKT values from their current entries, ``sigma``
and the penalties (a new numeric factorization on the same pattern: a new scaling or a
rho change refactors values only); :meth:`SparseKKT.solve` for one right-hand side,
refined. :meth:`SparseKKT.factor_gram` and :meth:`SparseKKT.solve_gram` are the
compressed-column counterpart of the dense path's Gram factor for cleaning primal
certificates (:func:`fccqp.certificates.gram_factor`).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from fccqp.sparse_equalities import column_gram
from fccqp.tuning import GRAM_REGULARIZATION, KKT_DELTA

DELTA = 1e-9
"""Quasi-definite regularization of the (2, 2) block (scaled problem)."""
BROKEN_DELTA = 1e-6
"""The regularization of a second factorization when the first met a zero pivot: rows
that depend on each other, beside a ``P`` flat but for ``sigma`` (1e-6), make ``(A H^-1
A')`` about 1e6 against ``delta = 1e-9``, and the second row's pivot, ``delta`` times a
factor of order one, is lost to rounding (the fuzzer's ``cvxpy:7``, a rank-one ``P``:
a zero pivot, reported as a non-convex QP). Refinement against the unregularized matrix
removes the larger bias as it removes the smaller one. On rows larger than one (a run
without equilibration) the third factorization scales it by the square of ``A``'s
largest entry (:meth:`SparseKKT._deltas`)."""
MAX_REFINE = 5
"""Most refinement steps per solve (and again after a cut of ``delta``)."""
DELTA_CUT = 1e-2
"""A refinement held back by ``delta`` refactors with this times the curvature its
contraction shows (:meth:`SparseKKT._cut_regularization`)."""
REFINE_TOLERANCE = 1e-13
"""Refine while ``||A x - b||`` (user's units) exceeds this times ``max(1, ||b||,
|| |A| |x| ||)``, the size of the terms of ``A x``: the rounding of ``A x`` itself is
``eps |A| |x|``, and on long rows (a row of 15000 ones in qpsolvers' sparse
least-squares test) that floor lies above ``1e-13 max(||b||, ||A x||)``, which the
dense backend's test uses (:data:`fccqp.tuning.KKT_REFINE_TOLERANCE`)."""
STATIONARITY_TOLERANCE = 1e-10
"""Refine also while the first block of the residual exceeds this times its terms (see
:meth:`SparseKKT._stationary`)."""
REGULARIZED_STEPS = 2
"""Refinement steps against the factored matrix when ``A x = b`` has no solution."""
FACTORED_TOLERANCE = 1e-8
"""A factorization whose refined solve misses the regularized matrix by more than this
times the terms of a row is taken for inaccurate (:meth:`SparseKKT._pivot`)."""


class FactorizationError(Exception):
    """``qdldl`` met a zero pivot (the matrix is not quasi-definite: a non-convex ``P``
    whose curvature cancels ``sigma`` exactly, or overflow)."""


class SparseKKT:
    """The x-update's KKT matrix on a fixed pattern, and its ``qdldl`` factorization.

    Parameters
    ----------
    P, A : scipy.sparse.csc_matrix
        The scaled problem's ``P`` (both triangles) and ``A``, over the arrays the
        compiled workspace scales in place (not copied: :meth:`factor` reads their
        current entries).
    constrained : (s,) int array
        The entries of ``x`` that carry a penalty.
    E : (m,) array
        Row scaling of ``A``, the workspace's (updated in place): the refinement's
        stopping test divides row ``i`` of ``A x - b`` by ``E_i`` (the user's units).
    """

    def __init__(self, P: sp.csc_matrix, A: sp.csc_matrix, constrained: np.ndarray,
                 E: np.ndarray) -> None:
        try:   # loaded when the sparse path first runs
            import qdldl
        except ImportError as exn:
            raise ImportError(
                "fccqp's sparse path (a KKT matrix above fccqp.settings.MAX_DENSE_KKT_ROWS "
                "rows, or kkt_backend='sparse') needs the qdldl package: pip install qdldl"
            ) from exn
        self._qdldl = qdldl
        self.P, self.A, self.E = P, A, E
        self.AT = A.T   # a CSR view over A's arrays
        n, m = P.shape[0], A.shape[0]
        self.n, self.m = n, m
        self.constrained = constrained
        # the upper triangle with every diagonal entry stored, zero or not, so that the
        # pattern stays the same whatever sigma and rho are; each entry of K is tagged
        # with its source (an entry of P, of A, or an added diagonal zero), so that
        # factor() assembles K's values with one gather
        coo = P.tocoo()
        self._upper = np.flatnonzero(coo.row <= coo.col)
        At = A.tocoo()
        stored = np.zeros(n, dtype=bool)
        stored[coo.row[coo.row == coo.col]] = True
        added = np.concatenate([np.flatnonzero(~stored), np.arange(n, n + m)])
        rows = np.concatenate([coo.row[self._upper], At.col, added])
        cols = np.concatenate([coo.col[self._upper], n + At.row, added])
        sources = len(rows)
        K = sp.csc_matrix((np.arange(1.0, sources + 1.0), (rows, cols)), shape=(n + m, n + m))
        K.sort_indices()
        self._source = K.data.astype(np.intp) - 1
        self._gathered = np.zeros(sources)
        self._K = K
        coo = K.tocoo()
        self._diagonal = np.flatnonzero(coo.row == coo.col)   # column order
        self._solver = None   # the factorization that solves: self._ldl or a pivoted one
        self._ldl = None   # qdldl's, updated in place by each factor
        self._pivoted = False   # whether this factorization is SuperLU's (_pivot)
        self._unchecked = True   # whether _least_squares has yet to check the solver
        self.abs_A = abs(A)
        self.abs_P = abs(P)
        self.penalty = np.zeros(n)   # sigma + rho on each entry of x, set by factor
        self.delta = DELTA   # the regularization factored, set by factor
        self._cut_spent = False   # whether this factorization's delta was cut once
        self._gram = None   # the qdldl factor of A A', set by factor_gram
        self._column_gram = None   # the qdldl factor of G G', set by factor_column_gram

    def factor(self, sigma: float, rho_vec: np.ndarray) -> int:
        """Factor for the current ``P`` and ``A``, ``sigma`` (on every entry of ``x``)
        and the penalties ``rho_vec`` on the constrained entries; return the number of
        negative pivots.

        A zero pivot is retried with the larger regularizations of :meth:`_deltas`;
        :class:`FactorizationError` when the last meets one too. So is a factorization
        whose pivots are not all finite and nonzero or that has fewer than ``m``
        negative ones, which no quasi-definite matrix has (Sylvester's law: its inertia
        is ``(n, m)`` for a positive definite ``P + sigma I + R``): ``qdldl``'s
        ``update`` reports no zero pivot, and after a rho change a pivot of ``-delta``
        lost to cancellation left 3 negative pivots of 9 and one of 0 (fuzz
        ``cvxpy:1700154``: every later solve wrong, the iterates grew by 1e19 every 25
        iterations to NUMERICAL_ERROR).
        """
        n, upper = self.n, self._upper.shape[0]
        gathered = self._gathered
        gathered[:upper] = self.P.data[self._upper]
        gathered[upper:upper + self.A.nnz] = self.A.data
        K = self._K
        np.take(gathered, self._source, out=K.data)
        diagonal = K.data[self._diagonal]
        diagonal[:n] += sigma
        diagonal[self.constrained] += rho_vec
        self.abs_A = abs(self.A)
        self.abs_P = abs(self.P)
        self._cut_spent = self._pivoted = False
        self._unchecked = True
        deltas = self._deltas()
        for self.delta in deltas:
            diagonal[n:] = -self.delta
            K.data[self._diagonal] = diagonal
            try:
                self._ldl, negative = self._quasi_definite(K, self._ldl)
                break
            except FactorizationError:
                self._solver = self._ldl = None
                if self.delta == deltas[-1]:
                    raise
        self._solver = self._ldl
        self.penalty = np.full(n, sigma)
        self.penalty[self.constrained] += rho_vec
        return negative

    def _deltas(self) -> tuple[float, ...]:
        """The regularizations :meth:`factor` tries in turn: ``DELTA``, ``BROKEN_DELTA``,
        and, where ``A`` has an entry larger than one, ``BROKEN_DELTA`` times its square.

        Without pivoting, a row eliminated after its variables has the pivot ``-delta``
        less ``A_i H^-1 A_i'`` (``H`` the eliminated block of ``P + sigma I + R``); of two
        rows dependent to rounding, the second's is the difference of two such terms,
        and their rounding, ``eps |A|^2 / sigma``, is below ``BROKEN_DELTA`` only for rows
        of order one, as equilibration makes them. Unequilibrated rows of 2e10 nearly
        parallel over entries that only ``sigma`` weighs (1e-6) left it at 1.7e10, of
        either sign, whatever ``BROKEN_DELTA``: a zero pivot, reported as a non-convex QP
        for a ``P`` positive semidefinite by construction. ``delta`` scaled with
        ``|A|^2`` stays that far above the rounding, and the refinement against the
        unregularized matrix removes its bias."""
        largest = float(np.max(np.abs(self.A.data), initial=0.0))
        if largest <= 1.0:
            return DELTA, BROKEN_DELTA
        return DELTA, BROKEN_DELTA, BROKEN_DELTA * largest * largest

    def _quasi_definite(self, K: sp.csc_matrix, solver: object) -> tuple[object, int]:
        """``qdldl``'s factorization of ``K`` (``solver`` updated, or a new one when None)
        and its number of negative pivots; :class:`FactorizationError` unless its pivots
        are those of a quasi-definite matrix (see :meth:`factor`)."""
        try:
            if solver is None:
                solver = self._qdldl.Solver(K, upper=True)
            else:
                solver.update(K, upper=True)
            _, d, _ = solver.factors()
        except RuntimeError as exn:   # qdldl's report of a zero pivot
            raise FactorizationError(str(exn)) from exn
        negative = int(np.count_nonzero(d < 0))
        if negative >= self.m and np.all(np.isfinite(d)) and np.all(d != 0.0):
            return solver, negative
        raise FactorizationError(f"{negative} negative pivots of {self.m}, or a zero one")

    def _cut_regularization(self, rate: float) -> tuple[object, float] | None:
        """Factor the current matrix again with ``delta`` cut to ``DELTA_CUT`` times the
        curvature that a refinement contracting by ``rate`` shows, ``delta (1 - rate) /
        rate``; the previous ``(factorization, delta)``, or None (nothing changed) when
        the cut one is not quasi-definite, a cut was already spent on this
        factorization, or it is pivoted (:meth:`_pivot`).

        A refinement against a factorization regularized by ``delta`` recovers, in a
        direction where ``A (P + sigma I + R)^-1 A'`` has the curvature ``c``, ``c / (c
        + delta)`` of the step a correction: where ``c`` lies below ``delta`` (``P``
        huge beside columns it does not touch, which the equilibration scales down to
        singular values of 1e-5 in ``A``, ``c`` about 1e-11) the correction contracts by
        ``rate = delta / (c + delta)``, close to 1, and the equality error stays at the
        size of its terms; that is no proof that ``A x = b`` has no solution."""
        if self._cut_spent or self._pivoted:
            return None
        self._cut_spent = True
        delta = DELTA_CUT * self.delta * (1.0 - rate) / rate
        try:
            solver, _ = self._quasi_definite(self._regularized(delta), None)
        except FactorizationError:
            return None
        previous = (self._solver, self.delta)
        self._solver, self.delta, self._unchecked = solver, delta, True
        return previous

    def _residual(self, rhs: np.ndarray, sol: np.ndarray, Ax: np.ndarray,
                  delta: float) -> np.ndarray:
        """``rhs - K sol`` for the matrix with ``-delta I`` as its (2, 2) block."""
        n = self.n
        x, nu = sol[:n], sol[n:]
        top = rhs[:n] - self.P @ x - self.penalty * x - self.AT @ nu
        return np.concatenate([top, rhs[n:] - Ax + delta * nu])

    def _stationary(self, rhs: np.ndarray, sol: np.ndarray, residual: np.ndarray) -> bool:
        """Whether the first block of ``residual`` (``rhs - K sol``) lies within
        ``STATIONARITY_TOLERANCE`` of its terms: without pivoting, a nearly singular ``P +
        sigma I + R`` (rho and sigma at 1e-6 beside a flat ``P``) left it at 5e-5 of them,
        and ADMM on those solves grew geometrically instead of along its ray (fuzz
        ``dual_infeasible:1700072``: NUMERICAL_ERROR where the dense LDL' certifies)."""
        n = self.n
        x, nu = np.abs(sol[:n]), np.abs(sol[n:])
        terms = np.abs(rhs[:n]) + self.abs_P @ x + self.penalty * x + self.abs_A.T @ nu
        return float(np.max(np.abs(residual[:n]))) <= STATIONARITY_TOLERANCE * max(
            1.0, float(np.max(terms)))

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """Solve the unregularized system for ``rhs`` (refined, see the module docstring)."""
        sol = self._solver.solve(rhs)
        n, E = self.n, self.E
        b = rhs[n:]
        last_error, step, previous, r = np.inf, None, None, 0
        while True:
            Ax = self.A @ sol[:n]
            residual = self._residual(rhs, sol, Ax, 0.0)
            error = float(np.max(np.abs(residual[n:]) / E, initial=0.0))
            size = float(np.max(np.maximum(np.abs(b), self.abs_A @ np.abs(sol[:n])) / E,
                                initial=0.0))
            met = error <= REFINE_TOLERANCE * max(1.0, size)
            if met and self._stationary(rhs, sol, residual):
                return sol
            if not met and error >= 0.5 * last_error:
                if previous is None and error < last_error:
                    previous = self._cut_regularization(error / last_error)
                    if previous is None:
                        return self._least_squares(rhs, sol - step)
                    r = 0
                else:
                    if previous is not None and r == 1:   # the cut's first step failed
                        self._solver, self.delta = previous
                    return self._least_squares(rhs, sol - step)
            last_error = error
            if r == MAX_REFINE:
                return sol
            r += 1
            step = self._solver.solve(residual)
            sol = sol + step

    def _least_squares(self, rhs: np.ndarray, sol: np.ndarray) -> np.ndarray:
        """``sol`` refined against the regularized matrix, whose least-squares ``x`` the
        equality certificate reads: where refinement against the unregularized one stops
        making progress, ``A x = b`` has no solution. Unless the factorization does not
        solve the regularized matrix itself (:meth:`_solves_regularized`, checked once
        per factorization): then the solve starts again on SuperLU's factorization of it
        (:meth:`_pivot`)."""
        for _ in range(REGULARIZED_STEPS):
            sol = sol + self._solver.solve(
                self._residual(rhs, sol, self.A @ sol[:self.n], self.delta))
        if self._unchecked:
            self._unchecked = False
            if not self._solves_regularized(rhs, sol) and self._pivot():
                return self.solve(rhs)
        return sol

    def _solves_regularized(self, rhs: np.ndarray, sol: np.ndarray) -> bool:
        """Whether ``sol`` solves the factored (regularized) matrix to
        ``FACTORED_TOLERANCE`` of the terms of each row."""
        n = self.n
        x, nu = sol[:n], sol[n:]
        residual = self._residual(rhs, sol, self.A @ x, self.delta)
        terms = np.abs(rhs) + np.concatenate([
            self.abs_P @ np.abs(x) + self.penalty * np.abs(x) + self.abs_A.T @ np.abs(nu),
            self.abs_A @ np.abs(x) + self.delta * np.abs(nu)])
        return bool(np.all(np.abs(residual) <= FACTORED_TOLERANCE * np.maximum(terms, 1.0)))

    def _pivot(self) -> bool:
        """Solve with SuperLU's factorization of the regularized matrix (partial
        pivoting) until the next :meth:`factor`; False (nothing changed) when it meets
        a zero pivot.

        Without pivoting, ``qdldl`` eliminates in its fill-reducing order whatever the
        pivots' sizes: an entry of ``x`` that only ``sigma`` weighs (1e-6; a zero
        column of ``P``, no penalty at the cold start), eliminated before the rows it
        meets, adds ``a a' / sigma`` (1e6) to their block, whose rounding (2e-10)
        buries both ``delta`` and the curvature of the other columns (1e-10, where
        ``P`` is huge and the equilibration scales its columns down): the factorization
        then solves neither the regularized matrix nor, refined, the system (residuals
        of the size of ``b``), and the point it leaves for inconsistent rows is not
        their least-squares one. Partial pivoting eliminates that entry with a row.

        Pivoted, the factorization's rounding no longer grows like ``1 / delta`` (see
        the module docstring), and it takes the dense backend's ``KKT_DELTA``: at
        ``DELTA`` the regularized point of rows whose curvature lies below it (2e-11
        unscaled beside ``P`` of 1e11) stays far from the least-squares one, and
        the equality certificate's cleaning step (:func:`fccqp.verdict.inconsistent`),
        which shrinks what is not in the null space of ``A'`` by ``delta / (c +
        delta)``, removes nothing. Nor is a pivoted ``delta`` cut
        (:meth:`_cut_regularization`): below ``KKT_DELTA`` a contraction stalled at
        rounding reads as curvature, and cuts to 1e-17 and below made the solves
        diverge."""
        delta = min(self.delta, KKT_DELTA)
        try:
            solver = self._pivoting(delta)
        except FactorizationError:
            return False
        self._solver, self.delta, self._pivoted = solver, delta, True
        return True

    def _regularized(self, delta: float) -> sp.csc_matrix:
        """The factored matrix's upper triangle with ``-delta I`` as its (2, 2) block (a
        copy)."""
        K = self._K.copy()
        K.data[self._diagonal[self.n:]] = -delta
        return K

    def _pivoting(self, delta: float) -> object:
        """SuperLU's factorization (partial pivoting) of the whole symmetric matrix with
        ``-delta I`` as its (2, 2) block; :class:`FactorizationError` at a zero pivot."""
        from scipy.sparse.linalg import splu

        upper = self._regularized(delta)
        try:
            return splu((upper + sp.triu(upper, 1).T).tocsc())
        except RuntimeError as exn:   # SuperLU's report of an exactly singular factor
            raise FactorizationError(str(exn)) from exn

    def factor_gram(self) -> bool:
        """Factor ``A A'`` of the current scaled ``A`` plus ``GRAM_REGULARIZATION`` of its
        largest diagonal entry (dependent rows), as the dense path's
        :func:`fccqp.certificates.gram_factor` does with Cholesky: sparse, ``m x m``,
        positive definite once regularized, factored by ``qdldl`` in its fill-reducing
        order. False when the diagonal is zero or a pivot is not positive and finite
        (where Cholesky fails)."""
        self._gram = None
        gram = (self.A @ self.AT).tocsc()
        largest = float(gram.diagonal().max(initial=0.0))
        if not largest > 0.0:
            return False
        gram = gram + sp.identity(self.m, format="csc") * (GRAM_REGULARIZATION * largest)
        try:
            solver = self._qdldl.Solver(sp.triu(gram, format="csc"), upper=True)
        except RuntimeError:   # qdldl's report of a zero pivot
            return False
        _, d, _ = solver.factors()
        if not np.all(np.isfinite(d) & (d > 0.0)):
            return False
        self._gram = solver
        return True

    def solve_gram(self, v: np.ndarray) -> np.ndarray:
        """``(A A' + regularization)^-1 v`` on the factor of :meth:`factor_gram`."""
        return self._gram.solve(v)

    def factor_column_gram(self, rows: np.ndarray) -> bool:
        """Factor the Gram matrix ``G G'`` of :func:`fccqp.sparse_equalities.column_gram`
        (``G = diag(1/rows) A diag(w)``, the columns of the scaled ``A`` divided by their
        largest entries), the compressed-column counterpart of the dense path's
        :func:`fccqp.equalities.column_gram`; ``rows`` (m) := the row norms. False when
        ``qdldl`` meets a zero pivot or a pivot that is not positive and finite."""
        self._column_gram = None
        _, norms, gram = column_gram(self.A)
        try:
            solver = self._qdldl.Solver(gram, upper=True)
        except RuntimeError:   # qdldl's report of a zero pivot
            return False
        _, d, _ = solver.factors()
        if not np.all(np.isfinite(d) & (d > 0.0)):
            return False
        rows[:] = norms
        self._column_gram = solver
        return True

    def solve_column_gram(self, v: np.ndarray) -> np.ndarray:
        """``(G G' + regularization)^-1 v`` on the factor of :meth:`factor_column_gram`."""
        return self._column_gram.solve(v)
