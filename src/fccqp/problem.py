"""Validation of user data into the dense arrays the solver works on."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numba import njit

from fccqp.cones import Cone, ConeArrays, flatten_cones

SYMMETRY_TOLERANCE = 1e-10
"""Relative asymmetry of ``P`` above which it is rejected rather than symmetrized."""


@dataclass(frozen=True)
class ProblemData:
    """A validated problem ``min 1/2 x'Px + q'x  s.t.  Ax = b, lb <= x <= ub, cones``.

    All arrays are dense, float64 and C-contiguous; ``P`` is exactly symmetric.
    ``constrained`` lists (ascending) the entries with a finite bound or in a cone:
    the only entries the ADMM splitting touches. ``cones`` has offsets into that list.
    """

    P: np.ndarray
    q: np.ndarray
    A: np.ndarray
    b: np.ndarray
    lb: np.ndarray
    ub: np.ndarray
    cones: ConeArrays
    constrained: np.ndarray

    @property
    def n(self) -> int:
        """Number of variables."""
        return int(self.q.shape[0])

    @property
    def m(self) -> int:
        """Number of equality rows."""
        return int(self.b.shape[0])


def _dense_matrix(value: object, name: str) -> np.ndarray:
    """Convert to a 2-D float64 array (densifying scipy.sparse), checking only the rank."""
    if type(value) is np.ndarray and value.dtype == np.float64 and value.ndim == 2:
        return value  # the control-loop case, at a tenth of the general path's cost
    if sp.issparse(value):
        value = value.toarray()
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exn:
        raise TypeError(f"{name} must be a numeric matrix: {exn}") from exn
    if array.ndim != 2:
        raise ValueError(f"{name} must be 2-dimensional, got shape {array.shape}")
    return array


def _vector(value: object, name: str, n: int) -> np.ndarray:
    if type(value) is np.ndarray and value.dtype == np.float64 and value.shape == (n,):
        return value
    if sp.issparse(value):
        value = value.toarray()
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exn:
        raise TypeError(f"{name} must be a numeric vector: {exn}") from exn
    if array.ndim != 1:
        if array.ndim > 2 or (array.ndim == 2 and 1 not in array.shape):
            raise ValueError(f"{name} must be a vector, got shape {array.shape}")
        array = array.reshape(-1)
    if array.shape[0] != n:
        raise ValueError(f"{name} must have {n} entries, got {array.shape[0]}")
    return array


# Codes of _scan's findings, turned into messages by _raise_finding.
_OK, _P_NOT_FINITE, _P_ASYMMETRIC, _NOT_FINITE, _NAN, _CROSSED, _INFINITE_SIDE = range(7)


@njit(cache=True)
def _scan(P, q, A, b, lb, ub, P_sym):
    """Check finiteness, symmetry and bounds in one scan (``P`` is read twice: once
    transposed into ``P_sym``, once row by row); fills ``P_sym`` with ``(P + P') / 2``.

    Returns ``(code, argument, index, value)``: ``argument`` numbers the vectors
    ``q, A, b, lb, ub`` as 0-4 and ``index`` locates the first offending entry.
    Entries of ``P`` that differ from their transpose by rounding are averaged.
    """
    n = P.shape[0]
    # Row by row with one accumulator per column, so that the inner loop vectorizes:
    # v - v is 0 for a finite v and NaN otherwise.
    P_sym[:, :] = P.T
    scale = np.ones(n)
    asymmetry = np.zeros(n)
    not_finite = np.zeros(n)
    for i in range(n):
        for j in range(n):
            v, t = P[i, j], P_sym[i, j]
            not_finite[j] += v - v
            scale[j] = max(scale[j], abs(v))
            asymmetry[j] = max(asymmetry[j], abs(v - t))
            P_sym[i, j] = 0.5 * (v + t)
    if not np.all(np.isfinite(not_finite)):
        for i in range(n):
            for j in range(n):
                if not np.isfinite(P[i, j]):
                    return _P_NOT_FINITE, -1, i, P[i, j]
    if asymmetry.max() > SYMMETRY_TOLERANCE * scale.max():
        return _P_ASYMMETRIC, -1, -1, asymmetry.max()
    for i in range(n):
        if not np.isfinite(q[i]):
            return _NOT_FINITE, 0, i, q[i]
    for i in range(A.shape[0]):
        for j in range(n):
            if not np.isfinite(A[i, j]):
                return _NOT_FINITE, 1, i, A[i, j]
        if not np.isfinite(b[i]):
            return _NOT_FINITE, 2, i, b[i]
    for i in range(n):
        if np.isnan(lb[i]):
            return _NAN, 3, i, lb[i]
        if np.isnan(ub[i]):
            return _NAN, 4, i, ub[i]
        if lb[i] > ub[i]:
            return _CROSSED, 3, i, lb[i]
        if lb[i] == np.inf:
            return _INFINITE_SIDE, 3, i, lb[i]
        if ub[i] == -np.inf:
            return _INFINITE_SIDE, 4, i, ub[i]
    return _OK, -1, -1, 0.0


@njit(cache=True)
def _constrained_entries(lb, ub, members, offset):
    """Entries with a finite bound or in a cone, ascending; the first cone member (in
    block order) with a finite bound, or -1; the cone offsets into the first list."""
    is_constrained = np.isfinite(lb) | np.isfinite(ub)
    bounded_member = -1
    for i in members:
        if is_constrained[i] and bounded_member < 0:
            bounded_member = i
        is_constrained[i] = True
    constrained = np.flatnonzero(is_constrained)
    return constrained, bounded_member, np.searchsorted(constrained, offset)


@njit(cache=True)
def same_entries(a, b):
    """True if the 2-D arrays ``a`` and ``b`` (same shape) are equal; exits at the first
    difference, which a control loop's changed matrices show at once."""
    for i in range(a.shape[0]):
        for j in range(a.shape[1]):
            if a[i, j] != b[i, j]:
                return False
    return True


def _raise_finding(code: int, argument: int, index: int, value: float, lb, ub) -> None:
    name = ("q", "A", "b", "lb", "ub")[argument] if argument >= 0 else "P"
    if code == _P_NOT_FINITE:
        raise ValueError(f"P contains NaN or inf (P[{index}, :] holds {value})")
    if code == _P_ASYMMETRIC:
        raise ValueError(
            f"P must be symmetric: max |P - P'| is {value:.3g} "
            f"(pass (P + P.T) / 2 if only its symmetric part matters)"
        )
    if code == _NOT_FINITE:
        where = f"row {index}" if name == "A" else f"index {index}"
        raise ValueError(f"{name} contains NaN or inf (at {where})")
    if code == _NAN:
        raise ValueError(f"{name} contains NaN (at index {index})")
    if code == _CROSSED:
        raise ValueError(
            f"lb > ub at index {index}: lb[{index}] = {lb[index]}, ub[{index}] = {ub[index]}"
        )
    raise ValueError(f"{name}[{index}] = {value}: lb may not be +inf and ub may not be -inf")


def validate(
    P: object,
    q: object,
    A: object = None,
    b: object = None,
    lb: object = None,
    ub: object = None,
    cones: Sequence[Cone] = (),
) -> ProblemData:
    """Check shapes and values of a problem and return it as :class:`ProblemData`.

    Raises
    ------
    TypeError, ValueError
        With the offending argument named: wrong shapes, NaN or inf in ``P, q, A, b``,
        NaN bounds, ``lb > ub``, non-symmetric ``P``, bad cones, or a finite bound on
        an entry of a cone block.
    """
    P = _dense_matrix(P, "P")
    if P.shape[0] != P.shape[1]:
        raise ValueError(f"P must be square, got shape {P.shape}")
    n = P.shape[0]
    if n == 0:
        raise ValueError("P must have at least one row (the problem has no variables)")
    q = _vector(q, "q", n)
    if (A is None) != (b is None):
        raise ValueError("A and b must be given together")
    if A is None:
        A, b = np.zeros((0, n)), np.zeros(0)
    else:
        A = _dense_matrix(A, "A")
        if A.shape[1] != n:
            raise ValueError(f"A must have {n} columns (the size of P), got shape {A.shape}")
        A = np.array(A, order="C")  # a private copy: the next solve compares against it
        b = _vector(b, "b", A.shape[0])
    lb = np.full(n, -np.inf) if lb is None else _vector(lb, "lb", n)
    ub = np.full(n, np.inf) if ub is None else _vector(ub, "ub", n)
    P_sym = np.empty((n, n))
    finding = _scan(P, q, A, b, lb, ub, P_sym)
    if finding[0] != _OK:
        _raise_finding(*finding, lb, ub)
    flat = flatten_cones(cones, n)
    constrained, bounded_member, position = _constrained_entries(lb, ub, flat.members, flat.offset)
    if bounded_member >= 0:
        i = bounded_member
        raise ValueError(
            f"x[{i}] is in a cone block and has a finite bound (lb[{i}] = {lb[i]}, "
            f"ub[{i}] = {ub[i]}); cone entries must have infinite bounds"
        )
    return ProblemData(P_sym, q, A, b, lb, ub, flat.relocated(position), constrained)
