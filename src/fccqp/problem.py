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
        array = np.array(value, dtype=np.float64, order="C")
    except (TypeError, ValueError) as exn:
        raise TypeError(f"{name} must be a numeric matrix: {exn}") from exn
    if array.ndim != 2:
        raise ValueError(f"{name} must be 2-dimensional, got shape {array.shape}")
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} contains NaN or inf")
    return array


def _vector(value: object, name: str, n: int, allow_inf: bool = False) -> np.ndarray:
    if sp.issparse(value):
        value = value.toarray()
    try:
        array = np.array(value, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError) as exn:
        raise TypeError(f"{name} must be a numeric vector: {exn}") from exn
    if np.ndim(value) > 2 or (np.ndim(value) == 2 and 1 not in np.shape(value)):
        raise ValueError(f"{name} must be a vector, got shape {np.shape(value)}")
    if array.shape[0] != n:
        raise ValueError(f"{name} must have {n} entries, got {array.shape[0]}")
    if np.any(np.isnan(array)) or (not allow_inf and not np.all(np.isfinite(array))):
        raise ValueError(f"{name} contains NaN" + ("" if allow_inf else " or inf"))
    return array


def _symmetric(P: np.ndarray) -> np.ndarray:
    """Return ``P`` made exactly symmetric, or raise if it is clearly not symmetric.

    Entries that differ by rounding (relative ``1e-10``) are averaged, as a user who
    built ``P = J'WJ`` in floating point expects; a real asymmetry is an error rather
    than silently replaced by ``(P + P')/2``.
    """
    asymmetry = float(np.max(np.abs(P - P.T), initial=0.0))
    scale = max(1.0, float(np.max(np.abs(P), initial=0.0)))
    if asymmetry > SYMMETRY_TOLERANCE * scale:
        raise ValueError(
            f"P must be symmetric: max |P - P'| is {asymmetry:.3g} "
            f"(pass (P + P.T) / 2 if only its symmetric part matters)"
        )
    return 0.5 * (P + P.T)


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
        b = _vector(b, "b", A.shape[0])
    lb = np.full(n, -np.inf) if lb is None else _vector(lb, "lb", n, allow_inf=True)
    ub = np.full(n, np.inf) if ub is None else _vector(ub, "ub", n, allow_inf=True)
    bad = np.flatnonzero(lb > ub)
    if bad.size:
        i = int(bad[0])
        raise ValueError(f"lb > ub at index {i}: lb[{i}] = {lb[i]}, ub[{i}] = {ub[i]}")
    if np.any(lb == np.inf) or np.any(ub == -np.inf):
        raise ValueError("lb may not be +inf and ub may not be -inf")
    flat = flatten_cones(cones, n)
    in_cone = flat.entries()
    bounded = np.isfinite(lb[in_cone]) | np.isfinite(ub[in_cone])
    if np.any(bounded):
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
