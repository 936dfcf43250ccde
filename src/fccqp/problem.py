"""Validation of user data: types and shapes here, numbers in the compiled scan.

:func:`convert` turns the arguments into dense float64 arrays and checks shapes and
types, naming the argument; :func:`structure` derives what the ADMM splitting needs
from the bounds and cones (the constrained entries, the fixed ones, the cone blocks).
The numeric checks (finite, symmetric, ``lb <= ub``, magnitudes) run in one pass over
the data inside the solve (:mod:`fccqp.validation`), and :func:`raise_finding` turns
its finding into the message.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from fccqp.cones import Cone, ConeArrays, flatten_cones
from fccqp.tuning import INFINITE_BOUND, MAX_ENTRY  # noqa: F401  (public here: docs/api.md)


class Sizes:
    """``n`` and ``m`` of a problem that has the vectors ``q`` (cost) and ``b`` (rows)."""

    @property
    def n(self) -> int:
        """Number of variables."""
        return int(self.q.shape[0])

    @property
    def m(self) -> int:
        """Number of equality rows."""
        return int(self.b.shape[0])


@dataclass(frozen=True)
class ProblemData(Sizes):
    """A converted problem ``min 1/2 x'Px + q'x  s.t.  Ax = b, lb <= x <= ub, cones``.

    All arrays are dense, float64 and C-contiguous (their numbers are checked by the
    solve). ``constrained`` lists (ascending) the entries with a finite bound or in a
    cone: the only entries the ADMM splitting touches; ``cones`` has offsets into that
    list and ``fixed`` marks the constrained entries with ``lb == ub``.
    """

    P: np.ndarray
    q: np.ndarray
    A: np.ndarray
    b: np.ndarray
    lb: np.ndarray
    ub: np.ndarray
    cones: ConeArrays
    constrained: np.ndarray
    fixed: np.ndarray


def issparse(value: object) -> bool:
    """``scipy.sparse.issparse(value)``, without importing scipy.sparse (0.2 s) when no
    caller did: a value cannot be a sparse matrix before the module is loaded."""
    sparse = sys.modules.get("scipy.sparse")
    return sparse is not None and sparse.issparse(value)


def _as_float_array(value: object, name: str, what: str) -> np.ndarray:
    """``value`` as a float64 array; complex, non-numeric or object data raise."""
    if issparse(value):
        value = value.toarray()
    try:
        array = np.asarray(value)
    except (TypeError, ValueError) as exn:
        raise TypeError(f"{name} must be a numeric {what}: {exn}") from exn
    if array.dtype.kind == "c":
        raise TypeError(f"{name} must be real, got a complex {what}")
    if array.dtype.kind not in "biuf":
        raise TypeError(f"{name} must be a numeric {what}, got dtype {array.dtype}")
    return np.ascontiguousarray(array, dtype=np.float64)


def dense_matrix(value: object, name: str) -> np.ndarray:
    """Convert to a C-contiguous 2-D float64 array (densifying scipy.sparse)."""
    if type(value) is np.ndarray and value.dtype == np.float64 and value.ndim == 2 \
            and value.flags.c_contiguous:
        return value  # the control-loop case, at a tenth of the general path's cost
    array = _as_float_array(value, name, "matrix")
    if array.ndim != 2:
        raise ValueError(f"{name} must be 2-dimensional, got shape {array.shape}")
    return array


def vector(value: object, name: str, n: int) -> np.ndarray:
    """Convert to a float64 vector of ``n`` entries (a row or column matrix is flattened)."""
    if type(value) is np.ndarray and value.dtype == np.float64 and value.shape == (n,) \
            and value.flags.c_contiguous:
        return value
    array = _as_float_array(value, name, "vector")
    if array.ndim != 1:
        if array.ndim > 2 or (array.ndim == 2 and 1 not in array.shape):
            raise ValueError(f"{name} must be a vector, got shape {array.shape}")
        array = array.reshape(-1)
    if array.shape[0] != n:
        raise ValueError(f"{name} must have {n} entries, got {array.shape[0]}")
    return array


def convert(
    P: object, q: object, A: object = None, b: object = None, lb: object = None,
    ub: object = None, *, matrix: Callable[[object, str], object] = dense_matrix,
) -> tuple:
    """Check types and shapes; return ``(P, q, A, b, lb, ub)``, the vectors as float64
    arrays and ``P``, ``A`` through ``matrix`` (:func:`dense_matrix`; the sparse path
    passes its CSC conversion).

    ``A, b`` default to zero rows and ``lb, ub`` to infinities. No copy is made of an
    argument that is already a contiguous float64 array of the right shape.
    """
    P = matrix(P, "P")
    if P.shape[0] != P.shape[1]:
        raise ValueError(f"P must be square, got shape {P.shape}")
    n = P.shape[0]
    if n == 0:
        raise ValueError("P must have at least one row (the problem has no variables)")
    q = vector(q, "q", n)
    if (A is None) != (b is None):
        raise ValueError("A and b must be given together")
    if A is None:
        A, b = np.zeros((0, n)), np.zeros(0)
    A = matrix(A, "A")
    if A.shape[1] != n:
        raise ValueError(f"A must have {n} columns (the size of P), got shape {A.shape}")
    b = vector(b, "b", A.shape[0])
    lb = np.full(n, -np.inf) if lb is None else vector(lb, "lb", n)
    ub = np.full(n, np.inf) if ub is None else vector(ub, "ub", n)
    return P, q, A, b, lb, ub


def structure(
    lb: np.ndarray, ub: np.ndarray, cones: Sequence[Cone], n: int
) -> tuple[np.ndarray, np.ndarray, ConeArrays]:
    """``(constrained, fixed, cones)``: the constrained entries (ascending), which of
    them have ``lb == ub``, and the cone blocks with offsets into ``constrained``.

    Raises ``ValueError`` when an entry of a cone block has a finite bound.
    """
    from fccqp.validation import structure_scan

    flat = flatten_cones(cones, n)
    constrained, fixed = np.empty(n, np.intp), np.empty(n, np.uint8)
    relocated = np.empty(flat.count, np.intp)
    count, _, member = structure_scan(lb, ub, flat.offset, flat.dim, constrained, fixed,
                                      relocated, 0)
    check_cone_bounds(member, lb, ub)
    return constrained[:count], fixed[:count].astype(bool), flat.relocated(relocated)


def check_cone_bounds(member: int, lb: np.ndarray, ub: np.ndarray) -> None:
    """Raise for ``member``, the first cone entry with a finite bound (-1: none)."""
    if member >= 0:
        raise ValueError(
            f"x[{member}] is in a cone block and has a finite bound (lb[{member}] = "
            f"{lb[member]}, ub[{member}] = {ub[member]}); cone entries must have infinite "
            "bounds"
        )


def validate(
    P: object, q: object, A: object = None, b: object = None, lb: object = None,
    ub: object = None, cones: Sequence[Cone] = (),
) -> ProblemData:
    """:func:`convert` and :func:`structure` in one call (the numbers are checked when
    the problem is solved)."""
    P, q, A, b, lb, ub = convert(P, q, A, b, lb, ub)
    constrained, fixed, flat = structure(lb, ub, cones, P.shape[0])
    return ProblemData(P, q, A, b, lb, ub, flat, constrained, fixed)


_ARGUMENTS = ("q", "A", "b", "lb", "ub")
_P_NOT_FINITE, _P_ASYMMETRIC, _NOT_FINITE, _NAN, _CROSSED, _INFINITE_SIDE, _TOO_LARGE = range(1, 8)


def raise_finding(finding: tuple[int, int, int, float], lb: np.ndarray, ub: np.ndarray) -> None:
    """Raise the ``ValueError`` for a finding ``(code, argument, index, value)`` of the
    compiled scan (codes of :mod:`fccqp.validation`)."""
    code, argument, index, value = finding
    name = _ARGUMENTS[argument] if argument >= 0 else "P"
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
    if code == _TOO_LARGE:
        where = f"row {index}" if name in ("A", "P") else f"index {index}"
        raise ValueError(
            f"{name} has an entry of magnitude {abs(value):.3g} (at {where}), beyond the "
            f"{MAX_ENTRY:.0e} that fccqp accepts: rescale the problem"
        )
    if code == _NAN:
        raise ValueError(f"{name} contains NaN (at index {index})")
    if code == _CROSSED:
        raise ValueError(
            f"lb > ub at index {index}: lb[{index}] = {lb[index]}, ub[{index}] = {ub[index]}"
        )
    if code == _INFINITE_SIDE:
        raise ValueError(f"{name}[{index}] = {value}: lb may not be +inf and ub may not be -inf")
    raise AssertionError(f"unknown validation code {code}")
