"""``A x = b`` at a stalled point of the sparse path: the projection of
:mod:`fccqp.equalities` over compressed columns.

The compiled core calls :func:`hold_equalities` (through :mod:`fccqp.kkt_sparse`, with
the GIL) on a point that ended MAX_ITER_REACHED or TIME_LIMIT_REACHED. Where a huge
``P`` makes the equilibration shrink its columns to ``D`` near 1e-9, the scaled rows have
singular values far below the KKT matrix's regularization ``delta`` and refinement
stalls: the point misses ``A x = b`` by units (fuzz ``extreme_data`` 689 forced to the
sparse backend: 12.4). The projection is the dense module's: ``x += diag(w)^2 A' v``
with ``(G G') v = diag(1/r) (b - A x)``, ``G = diag(1/r) A diag(w)``, ``w`` the
reciprocal column norms and ``r`` the row norms after them, so that the Gram matrix
is about as well conditioned as the user's ``A``; ``G G'`` (sparse, ``m x m``, positive
definite once regularized) is factored by ``qdldl``, the sparse backend's library.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from fccqp.tuning import EQUALITY_MISSED, GRAM_REGULARIZATION, KKT_REFINE_TOLERANCE, MAX_REFINE


def _error(A: sp.csc_matrix, E: np.ndarray, x: np.ndarray,
           b: np.ndarray) -> tuple[np.ndarray, float, float]:
    """``(b - A x, its largest entry in the user's units, the size of the terms)``: as
    the dense module's ``_equality_error``, rows divided by their scaling ``E``."""
    r = b - A @ x
    terms = (np.abs(b) + abs(A) @ np.abs(x)) / E
    return r, float(np.max(np.abs(r) / E)), max(1.0, float(terms.max()))


def column_gram(A: sp.csc_matrix) -> tuple[np.ndarray, np.ndarray, sp.csc_matrix]:
    """``(w, rows, G G' + GRAM_REGULARIZATION max diag)`` for ``G = diag(1/rows) A
    diag(w)`` (1 for an empty column's ``w`` and an empty row's norm)."""
    magnitude = abs(A)
    w = magnitude.max(axis=0).toarray().ravel()
    w = np.divide(1.0, w, out=np.ones_like(w), where=w > 0)
    rows = (magnitude @ sp.diags(w)).max(axis=1).toarray().ravel()
    rows[~(rows > 0)] = 1.0
    G = sp.diags(1.0 / rows) @ A @ sp.diags(w)
    gram = (G @ G.T).tocsc()
    largest = float(gram.diagonal().max(initial=0.0))
    gram = gram + sp.identity(A.shape[0], format="csc") * (GRAM_REGULARIZATION * max(
        largest, 1.0))
    return w, rows, sp.triu(gram, format="csc")


def hold_equalities(A: sp.csc_matrix, E: np.ndarray, x: np.ndarray, b: np.ndarray) -> None:
    """Project ``x`` (scaled, changed in place) onto ``A x = b`` when it misses it beyond
    ``EQUALITY_MISSED`` of its terms: up to ``MAX_REFINE`` projections, until
    ``KKT_REFINE_TOLERANCE`` of the terms, each kept only while it reduces the error
    (inconsistent rows keep the least-squares point the KKT solves left)."""
    if A.shape[0] == 0:
        return
    r, error, scale = _error(A, E, x, b)
    if error <= EQUALITY_MISSED * scale:
        return
    import qdldl  # present: the sparse backend that ran uses it
    w, rows, gram = column_gram(A)
    try:
        factor = qdldl.Solver(gram, upper=True)
    except RuntimeError:   # a zero pivot: the rows' Gram matrix could not be factored
        return
    for _ in range(MAX_REFINE):
        saved = x.copy()
        v = factor.solve(r / rows) / rows
        x += w * w * (A.T @ v)
        r, new_error, scale = _error(A, E, x, b)
        if not new_error < error:
            x[:] = saved
            return
        error = new_error
        if error <= KKT_REFINE_TOLERANCE * scale:
            return
