"""Problem data of the sparse path: conversion and validation.

The sparse path (:meth:`fccqp.Solver._solve_sparse`) serves problems too large for the
dense core's KKT matrix: the compiled core on a workspace that holds ``P`` and ``A`` in
compressed columns. This module converts its arguments to ``scipy.sparse`` CSC
matrices (``P`` with its full symmetric pattern, whose arrays the workspace takes) and
checks them with the dense path's rules and messages (see :mod:`fccqp.problem` and
:mod:`fccqp.validation`: finite entries, magnitudes up to ``MAX_ENTRY``, a symmetric
``P`` up to rounding, ``lb <= ub``, bounds beyond ``INFINITE_BOUND`` are infinite).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from fccqp import problem as dense_problem
from fccqp.cones import Cone, ConeArrays
from fccqp.problem import Sizes, raise_finding, structure
from fccqp.tuning import (
    INFINITE_BOUND,
    MAX_ENTRY,
    SYMMETRY_TOLERANCE,
)


@dataclass(frozen=True)
class SparseData(Sizes):
    """``min 1/2 x'Px + q'x  s.t.  A x = b, lb <= x <= ub, x[block] in cone``, sparse.

    ``P`` (both triangles, symmetrized) and ``A`` are CSC float64 matrices, the vectors
    dense; infinite bounds are ``-inf`` / ``inf``. ``constrained`` lists (ascending)
    the entries with a finite bound or in a cone, ``fixed`` marks those with ``lb ==
    ub``, and ``cones`` has offsets into ``constrained`` (as :func:`fccqp.problem.structure`
    returns them).
    """

    P: sp.csc_matrix
    q: np.ndarray
    A: sp.csc_matrix
    b: np.ndarray
    lb: np.ndarray
    ub: np.ndarray
    cones: ConeArrays
    constrained: np.ndarray
    fixed: np.ndarray


def _sparse_matrix(value: object, name: str) -> sp.csc_matrix:
    """``value`` (``scipy.sparse``, array or nested lists) as a CSC float64 matrix with
    sorted indices and no explicit zeros; type errors name the argument."""
    if sp.issparse(value):
        if value.dtype.kind == "c":
            raise TypeError(f"{name} must be real, got a complex matrix")
        if value.dtype.kind not in "biuf":
            raise TypeError(f"{name} must be a numeric matrix, got dtype {value.dtype}")
        if value.ndim != 2:
            raise ValueError(f"{name} must be 2-dimensional, got shape {value.shape}")
        matrix = sp.csc_matrix(value, dtype=np.float64, copy=True)
    else:
        matrix = sp.csc_matrix(dense_problem.dense_matrix(value, name))
    matrix.sum_duplicates()
    matrix.eliminate_zeros()
    matrix.sort_indices()
    return matrix


def _finite_entries(M: sp.csc_matrix, argument: int, name: str) -> None:
    """Raise for the first NaN or inf stored entry of ``M``, else its first too large
    one, or for ``P`` the first of its largest (by row, as the dense scan reports them;
    ``argument`` is the code :func:`raise_finding` names)."""
    bad = ~np.isfinite(M.data)
    code = dense_problem._P_NOT_FINITE if name == "P" else dense_problem._NOT_FINITE
    if not bad.any():
        magnitude = np.abs(M.data)
        bad = magnitude > MAX_ENTRY
        if name == "P" and bad.any():
            bad = magnitude == magnitude.max()
        code = dense_problem._TOO_LARGE
    if bad.any():
        coo = M.tocoo()
        found = np.flatnonzero(bad)
        first = int(found[np.argmin(coo.row[found])])
        raise_finding((code, argument, int(coo.row[first]), float(coo.data[first])),
                      np.empty(0), np.empty(0))


def _finite_vector(v: np.ndarray, argument: int) -> None:
    bad = ~np.isfinite(v)
    code = dense_problem._NOT_FINITE
    if not bad.any():
        bad, code = np.abs(v) > MAX_ENTRY, dense_problem._TOO_LARGE
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise_finding((code, argument, i, float(v[i])), np.empty(0), np.empty(0))


def _bounds(lb: np.ndarray, ub: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Check the bounds as :func:`fccqp.validation.scan_and_copy` does; return copies with
    bounds beyond ``INFINITE_BOUND`` made infinite."""
    checks = (
        (np.isnan(lb), dense_problem._NAN, 3, lb),
        (np.isnan(ub), dense_problem._NAN, 4, ub),
        (lb > ub, dense_problem._CROSSED, 3, lb),
        (lb == np.inf, dense_problem._INFINITE_SIDE, 3, lb),
        (ub == -np.inf, dense_problem._INFINITE_SIDE, 4, ub),
    )
    for bad, code, argument, values in checks:
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise_finding((code, argument, i, float(values[i])), lb, ub)
    return (np.where(lb > -INFINITE_BOUND, lb, -np.inf),
            np.where(ub < INFINITE_BOUND, ub, np.inf))


def convert(
    P: object, q: object, A: object = None, b: object = None, lb: object = None,
    ub: object = None, cones: Sequence[Cone] = (),
) -> SparseData:
    """Check the problem and return it as :class:`SparseData`.

    Accepts what :func:`fccqp.solve` accepts. Malformed input raises ``ValueError`` or
    ``TypeError`` naming the argument, with the dense path's messages; ``P`` is
    replaced by ``(P + P') / 2`` when its asymmetry is below
    ``SYMMETRY_TOLERANCE`` times its largest entry, and rejected above.
    """
    P, q, A, b, lb, ub = dense_problem.convert(P, q, A, b, lb, ub, matrix=_sparse_matrix)
    # private copies: the caller may refill its arrays before the next solve
    q, b, lb, ub = (np.array(v) for v in (q, b, lb, ub))
    n = P.shape[0]
    _finite_entries(P, -1, "P")
    asymmetry = abs(P - P.T).max() if P.nnz else 0.0
    if asymmetry > SYMMETRY_TOLERANCE * abs(P).max():
        raise_finding((dense_problem._P_ASYMMETRIC, -1, -1, float(asymmetry)), lb, ub)
    P = ((P + P.T) * 0.5).tocsc()
    P.sort_indices()
    _finite_entries(A, 1, "A")
    _finite_vector(q, 0)
    _finite_vector(b, 2)
    lb, ub = _bounds(lb, ub)
    constrained, fixed, flat = structure(lb, ub, cones, n)
    return SparseData(P, q, A, b, lb, ub, flat, constrained, fixed)
