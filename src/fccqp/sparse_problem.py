"""Problem data of the sparse path: conversion, validation and Ruiz equilibration.

The sparse path (:mod:`fccqp.sparse_admm`) serves problems too large for the dense
core's KKT matrix. Its data stay ``scipy.sparse`` CSC matrices throughout; this module
converts and checks them with the dense path's rules and messages (see
:mod:`fccqp.problem` and :mod:`fccqp.validation`: finite entries, magnitudes up to
``MAX_ENTRY``, a symmetric ``P`` up to rounding, ``lb <= ub``, bounds beyond
``INFINITE_BOUND`` are infinite) and equilibrates them as :mod:`fccqp.scaling` does,
with vectorized column norms in place of the dense loops.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from fccqp import problem as dense_problem
from fccqp.cones import Cone, ConeArrays
from fccqp.problem import Sizes, raise_finding, structure
from fccqp.projections import project_constraint_set
from fccqp.tuning import (
    INFINITE_BOUND,
    MAX_ENTRY,
    MAX_NORM,
    MIN_COST_NORM,
    MIN_NORM,
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
    """Raise for the first NaN, inf or too large stored entry of ``M`` (by row, as the
    dense scan reports it; ``argument`` is the code :func:`raise_finding` names)."""
    bad = ~np.isfinite(M.data)
    code = dense_problem._P_NOT_FINITE if name == "P" else dense_problem._NOT_FINITE
    if not bad.any():
        bad = np.abs(M.data) > MAX_ENTRY
        code = dense_problem._TOO_LARGE
    if bad.any():
        coo = M.tocoo()
        first = int(np.argmin(np.where(bad, coo.row, np.iinfo(np.int64).max)))
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


@dataclass(frozen=True)
class Scaled(Sizes):
    """The equilibrated problem ``P_s = c D P D``, ``q_s = c D q``, ``A_s = E A D``,
    ``b_s = E b``, bounds of ``x_S`` divided by ``D_S`` (see :mod:`fccqp.scaling`), with
    what the iteration, the checks and polishing read from it: the structure of the
    splitting, ``A'`` and the entrywise magnitudes of ``P``, ``A`` and ``A'`` (the terms
    that the certificates weigh), and each row's span over the box
    (:func:`fccqp.termination.row_spans`)."""

    P: sp.csc_matrix
    q: np.ndarray
    A: sp.csc_matrix
    b: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    D: np.ndarray
    E: np.ndarray
    c: float
    constrained: np.ndarray
    """The ``s`` constrained entries of ``x``."""
    in_cone: np.ndarray
    """``s`` flags: the constrained entry belongs to a cone block."""
    cones: tuple
    """``(kind, offset, dim, mu, normal)`` of :class:`fccqp.cones.ConeArrays`, offsets
    into the constrained entries: the argument of
    :func:`fccqp.projections.project_constraint_set`."""
    AT: sp.csc_matrix
    abs_P: sp.csc_matrix
    abs_A: sp.csc_matrix
    abs_AT: sp.csc_matrix
    span: np.ndarray
    """Range of each row's ``A x`` over the box (infinite where a row meets an entry
    without two finite bounds)."""

    @property
    def s(self) -> int:
        """Number of constrained entries."""
        return int(self.constrained.shape[0])

    def project(self, v: np.ndarray) -> np.ndarray:
        """``P_C(v)`` for ``v`` on the constrained entries: clip to the box, project each
        cone block (the compiled kernels of :mod:`fccqp.projections`)."""
        out = np.empty_like(v)
        project_constraint_set(np.ascontiguousarray(v), self.lo, self.hi, self.cones, out)
        return out

    def project_cones(self, v: np.ndarray) -> np.ndarray:
        """``v`` with each cone block projected onto its cone, the rest unchanged."""
        out = np.empty_like(v)
        free = np.full(v.shape[0], np.inf)
        project_constraint_set(np.ascontiguousarray(v), -free, free, self.cones, out)
        return out


def _inverse_sqrt_norm(norm: np.ndarray) -> np.ndarray:
    """Ruiz's factor per column: ``1/sqrt(norm)``, 1 below ``MIN_NORM``, the norm capped
    at ``MAX_NORM`` (as :mod:`fccqp.scaling`)."""
    return np.where(norm < MIN_NORM, 1.0,
                    1.0 / np.sqrt(np.clip(norm, MIN_NORM, MAX_NORM)))


def _column_max(M: sp.csc_matrix, row_weight: np.ndarray | None = None) -> np.ndarray:
    """Largest ``|M_ij| w_i`` of each column ``j`` of the CSC matrix ``M`` (0 for an empty
    column), ``w`` the ``row_weight`` (ones by default): one pass over the stored
    entries, no product of matrices."""
    values = np.abs(M.data)
    if row_weight is not None:
        values = values * row_weight[M.indices]
    counts = np.diff(M.indptr)
    out = np.zeros(M.shape[1])
    filled = counts > 0
    if filled.any():
        out[filled] = np.maximum.reduceat(values, M.indptr[:-1][filled])
    return out


def equilibrate(data: SparseData, passes: int, previous: Scaled | None = None) -> Scaled:
    """Ruiz equilibration of ``[[P, A'], [A, 0]]`` and cost normalization, as
    :func:`fccqp.scaling.equilibrate` does: each pass divides every column by the square
    root of its infinity norm, ``D`` constant (geometric mean) over each cone block so
    that a scaled cone is the same cone, then ``c`` normalizes the cost. With
    ``previous`` (the scaling of the same ``P`` and ``A``) its ``D``, ``E`` and ``c``
    are applied to the new vectors and bounds instead."""
    if previous is not None:
        return _assemble(data, previous.P, previous.A, previous.D, previous.E, previous.c)
    P, A = data.P, data.A
    A_rows = A.T.tocsc()   # the rows of A as columns
    D, E = np.ones(data.n), np.ones(data.m)
    starts = data.constrained[data.cones.offset]
    for _ in range(passes):
        # the norms of the current D P D and E A D, read off the original entries
        d = _inverse_sqrt_norm(D * np.maximum(_column_max(P, D), _column_max(A, E)))
        e = _inverse_sqrt_norm(E * _column_max(A_rows, D))
        for start, dim in zip(starts, data.cones.dim, strict=True):
            block = slice(start, start + dim)
            d[block] = np.exp(np.mean(np.log(d[block])))
        D *= d
        E *= e
    Ds, Es = sp.diags(D), sp.diags(E)
    P_s = (Ds @ P @ Ds).tocsc()
    A_s = (Es @ A @ Ds).tocsc()
    mean_col = float(np.mean(_column_max(P_s)))
    q_norm = float(np.max(np.abs(D * data.q), initial=0.0))
    size = max(mean_col if mean_col >= MIN_COST_NORM else 1.0,
               q_norm if q_norm >= MIN_COST_NORM else 1.0)
    c = 1.0 / min(size, MAX_NORM)
    P_s = (P_s * c).tocsc()
    P_s.sort_indices()
    A_s.sort_indices()
    return _assemble(data, P_s, A_s, D, E, c)


def _assemble(data: SparseData, P_s: sp.csc_matrix, A_s: sp.csc_matrix, D: np.ndarray,
              E: np.ndarray, c: float) -> Scaled:
    """The :class:`Scaled` problem from the scaled matrices and the scaling."""
    n = data.n
    q_s, b_s = D * data.q, E * data.b
    S = data.constrained
    lo, hi = data.lb[S] / D[S], data.ub[S] / D[S]
    cones = data.cones
    in_cone = np.zeros(len(S), dtype=bool)
    in_cone[cones.members] = True
    width = np.full(n, np.inf)
    width[S] = hi - lo
    abs_A = abs(A_s).tocsc()
    return Scaled(
        P_s, q_s * c, A_s, b_s, lo, hi, D, E, c, S, in_cone,
        (cones.kind, cones.offset, cones.dim, cones.mu, cones.normal),
        A_s.T.tocsc(), abs(P_s).tocsc(), abs_A, abs_A.T.tocsc(), abs_A @ width,
    )
