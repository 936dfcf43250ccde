"""Validation of user data into the dense arrays the solver works on."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

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
    if sp.issparse(value):
        value = value.toarray()
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exn:
        raise TypeError(f"{name} must be a numeric matrix: {exn}") from exn
    if array.ndim != 2:
        raise ValueError(f"{name} must be 2-dimensional, got shape {array.shape}")
    return array


def _vector(value: object, name: str, n: int, allow_inf: bool = False) -> np.ndarray:
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
    if allow_inf:
        if np.isnan(array).any():
            raise ValueError(f"{name} contains NaN")
    elif not np.isfinite(array).all():
        raise ValueError(f"{name} contains NaN or inf")
    return array


def _symmetric(P: np.ndarray) -> np.ndarray:
    """Return ``P`` made exactly symmetric, or raise if it is not finite and symmetric.

    Entries that differ by rounding (relative ``1e-10``) are averaged, as a user who
    built ``P = J'WJ`` in floating point expects; a real asymmetry is an error rather
    than silently replaced by ``(P + P')/2``. A NaN or inf entry makes the asymmetry
    non-finite, so one pass checks both.
    """
    with np.errstate(invalid="ignore"):
        difference = P - P.T
    asymmetry = float(np.abs(difference).max(initial=0.0))
    if not np.isfinite(asymmetry):
        raise ValueError("P contains NaN or inf")
    scale = max(1.0, float(np.abs(P).max(initial=0.0)))
    if asymmetry > SYMMETRY_TOLERANCE * scale:
        raise ValueError(
            f"P must be symmetric: max |P - P'| is {asymmetry:.3g} "
            f"(pass (P + P.T) / 2 if only its symmetric part matters)"
        )
    return P - 0.5 * difference


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
    P = _symmetric(P)
    q = _vector(q, "q", n)
    if (A is None) != (b is None):
        raise ValueError("A and b must be given together")
    if A is None:
        A, b = np.zeros((0, n)), np.zeros(0)
    else:
        A = _dense_matrix(A, "A")
        if A.shape[1] != n:
            raise ValueError(f"A must have {n} columns (the size of P), got shape {A.shape}")
        if not np.isfinite(A).all():
            raise ValueError("A contains NaN or inf")
        A = np.ascontiguousarray(A)
        b = _vector(b, "b", A.shape[0])
    lb = np.full(n, -np.inf) if lb is None else _vector(lb, "lb", n, allow_inf=True)
    ub = np.full(n, np.inf) if ub is None else _vector(ub, "ub", n, allow_inf=True)
    if (lb > ub).any():
        i = int(np.flatnonzero(lb > ub)[0])
        raise ValueError(f"lb > ub at index {i}: lb[{i}] = {lb[i]}, ub[{i}] = {ub[i]}")
    if (lb == np.inf).any() or (ub == -np.inf).any():
        raise ValueError("lb may not be +inf and ub may not be -inf")
    flat = flatten_cones(cones, n)
    in_cone = flat.entries()
    bounded = np.isfinite(lb[in_cone]) | np.isfinite(ub[in_cone])
    if bounded.any():
        i = int(in_cone[np.flatnonzero(bounded)[0]])
        raise ValueError(
            f"x[{i}] is in a cone block and has a finite bound (lb[{i}] = {lb[i]}, "
            f"ub[{i}] = {ub[i]}); cone entries must have infinite bounds"
        )
    is_constrained = np.isfinite(lb) | np.isfinite(ub)
    is_constrained[in_cone] = True
    constrained = np.flatnonzero(is_constrained).astype(np.int64)
    position = np.searchsorted(constrained, flat.offset)
    return ProblemData(P, q, A, b, lb, ub, flat.relocated(position), constrained)
