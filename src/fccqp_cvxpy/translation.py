"""Translation between CVXPY's conic form and fccqp's cone-plus-box form.

CVXPY hands a conic solver the problem

.. math::

    \\min_x \\tfrac12 x'Px + c'x \\quad\\text{s.t.}\\quad A x + s = b,\\; s \\in K,

with ``K = {0}^zero x R_+^nonneg x SOC(d_1) x ... x SOC(d_k)``, the rows of ``A``
ordered in that way and each second-order block ordered ``[t, v_1, ..., v_{d-1}]``
(``||v|| <= t``). It expects duals ``z`` with ``P x + c + A'z = 0`` and ``z in K*``.

fccqp solves ``min 1/2 v'P_f v + q'v  s.t.  A_f v = b_f, lb <= v <= ub, v[block] in cone``
with the equalities exact at every iterate and the box and cones handled by
projections, which is cheapest when the box and cones act on the variables
themselves. :func:`translate` therefore maps each CVXPY row group as follows.

Zero rows
    Kept as equalities ``A_i x = b_i``. Their CVXPY dual is fccqp's ``y_i``.
Variable bounds (``BOUNDED_VARIABLES``)
    CVXPY passes ``cp.Variable(bounds=...)`` and ``nonneg=True`` as per-column
    ``lower``/``upper`` arrays; they become fccqp's box as they are. Columns with a
    finite variable bound are not mapped into native cones.
Nonnegative rows that are a simple bound
    A row with a single nonzero ``a`` in column ``j`` says ``a x_j <= b_i``: an upper
    bound ``b_i / a`` if ``a > 0``, a lower bound if ``a < 0``. Several bounds on one
    entry merge into the tightest pair. The bound that is active carries fccqp's box
    multiplier ``z_j``; matching the stationarity terms ``a z_i = z_j`` gives the
    CVXPY dual ``z_i = z_j / a`` (the other bound rows of that entry get 0). Entries
    that belong to a mapped cone block, or whose merged bounds cross (``lb > ub``, an
    infeasible problem), keep their bound rows as general rows.
Second-order blocks that are scaled entries of ``x``
    A block with zero offset whose rows are ``s_k = alpha_k x_{j_k}`` for distinct,
    otherwise unused columns, ``alpha_0 > 0`` and ``|alpha_1| = ... = |alpha_{d-1}|``,
    is the cone ``||x_v|| <= (alpha_0 / |alpha_1|) x_t`` on the variables themselves.
    For ``d = 3`` it becomes a native :class:`fccqp.FrictionCone` with
    ``mu = alpha_0 / |alpha_1|`` on the block ``(x_{j_1}, x_{j_2}, x_{j_0})`` (normal
    last), which is what ``cp.SOC(mu * f[2], f[:2])`` produces; for other ``d`` with
    ``alpha_0 = |alpha_1|`` a :class:`fccqp.SecondOrderCone` on ``(x_{j_0}, ...)``.
    Stationarity ``-alpha_k z_k = z_{j_k}`` gives the CVXPY dual ``z_k = -z_{j_k} /
    alpha_k``. The columns are reordered so that every mapped block is contiguous.
Every other nonnegative or second-order row
    Gets a slack variable ``s_i = b_i - A_i x`` appended to ``v``: the equality
    ``A_i x + s_i = b_i`` joins ``A_f`` and ``s_i >= 0`` becomes the bound ``lb = 0``,
    or the slack block joins a :class:`fccqp.SecondOrderCone`. Stationarity in the
    slack, ``y_i + z_{s_i} = 0``, and in ``x`` shows the CVXPY dual is ``y_i``.

The translated variable vector is ``v = [x[perm]; slacks]`` and the recovered primal
is ``x[perm] = v[:n]``. Slacks have zero cost, so both problems have the same
objective value.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import partial

import numpy as np
import scipy.sparse as sp

from fccqp import FrictionCone, SecondOrderCone
from fccqp.cones import Cone

_SCALE_RTOL = 1e-12
"""Relative tolerance when checking that the tangential scales of a cone block agree."""


@dataclass(frozen=True)
class ConeDims:
    """Sizes of CVXPY's cone blocks, in CVXPY's row order."""

    zero: int
    """Number of equality rows (first)."""
    nonneg: int
    """Number of nonnegative rows (next)."""
    soc: tuple[int, ...]
    """Dimension of each second-order block (last), each ordered ``[t, v...]``."""


@dataclass(frozen=True)
class Translation:
    """A CVXPY conic problem in fccqp's form, plus the maps back.

    The arrays ``P, q, A, b, lb, ub`` and ``cones`` are arguments of
    :meth:`fccqp.Solver.solve`. The remaining fields recover CVXPY's primal
    and dual solution (see :func:`recover_primal` and :func:`recover_duals`).
    """

    P: np.ndarray
    """Cost matrix over ``v``: ``P[perm][:, perm]`` padded with zero slack rows/columns."""
    q: np.ndarray
    """Linear cost over ``v``: ``c[perm]`` then zeros."""
    A: np.ndarray
    """Equality rows: CVXPY's zero rows, then one row per slack."""
    b: np.ndarray
    """Right-hand side of :attr:`A`."""
    lb: np.ndarray
    """Lower bounds on ``v`` (mapped bounds, 0 on nonnegative slacks, else ``-inf``)."""
    ub: np.ndarray
    """Upper bounds on ``v`` (mapped bounds, else ``+inf``)."""
    cones: tuple[Cone, ...]
    """Native cones on permuted variables, then second-order cones on slack blocks."""
    perm: np.ndarray
    """``v[:n] = x[perm]``."""
    num_rows: int
    """Number of rows ``m`` of CVXPY's ``A`` (length of its dual vector)."""
    y_rows: np.ndarray
    """CVXPY row of each fccqp equality row: its dual is fccqp's ``y``."""
    cone_rows: np.ndarray
    """CVXPY rows of mapped cone blocks."""
    cone_vars: np.ndarray
    """Entry of ``v`` each row of :attr:`cone_rows` scales."""
    cone_scale: np.ndarray
    """``-1 / alpha``: CVXPY dual of the row is ``z[cone_vars] * cone_scale``."""
    bound_rows: np.ndarray
    """CVXPY rows that define the merged bound of an entry (one per entry and side)."""
    bound_vars: np.ndarray
    """Entry of ``v`` each row of :attr:`bound_rows` bounds."""
    bound_scale: np.ndarray
    """``1 / a``: CVXPY dual of the row is ``z[bound_vars] * bound_scale`` when active."""
    bound_side: np.ndarray
    """``+1`` for an upper bound, ``-1`` for a lower bound."""

    @property
    def num_slacks(self) -> int:
        """Number of slack variables appended to ``x``."""
        return int(self.q.shape[0] - self.perm.shape[0])

    @property
    def structure(self) -> tuple:
        """Hashable summary of the layout; warm starts are only valid within one layout."""
        return (
            self.q.shape[0], self.b.shape[0], self.perm.tobytes(), self.y_rows.tobytes(),
            self.cones,
        )


@dataclass(frozen=True)
class _MappedCone:
    rows: np.ndarray  # CVXPY rows, in block order [t, v...]
    cols: np.ndarray  # column of x in each row
    alpha: np.ndarray  # s_k = alpha_k x_{cols_k}


def _single_entries(A: sp.csr_array) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per row: number of nonzeros, and the column and value of its first nonzero."""
    counts = np.diff(A.indptr)
    first = np.minimum(A.indptr[:-1], max(A.nnz - 1, 0))
    if A.nnz == 0:
        return counts, np.zeros_like(counts), np.zeros(counts.shape[0])
    return counts, A.indices[first], A.data[first]


def _mappable_cone(
    rows: np.ndarray, counts: np.ndarray, cols: np.ndarray, vals: np.ndarray,
    b: np.ndarray, used: np.ndarray,
) -> _MappedCone | None:
    """The block as scaled entries of ``x``, or ``None`` if it needs slacks."""
    if np.any(counts[rows] != 1) or np.any(b[rows] != 0.0):
        return None
    block_cols = cols[rows]
    if np.unique(block_cols).shape[0] != rows.shape[0] or used[block_cols].any():
        return None
    alpha = -vals[rows]
    tangential = np.abs(alpha[1:])
    if alpha[0] <= 0 or not np.allclose(tangential, tangential[0], rtol=_SCALE_RTOL, atol=0):
        return None
    if rows.shape[0] != 3 and not np.isclose(alpha[0], tangential[0], rtol=_SCALE_RTOL, atol=0):
        return None
    return _MappedCone(rows, block_cols, alpha)


def _native_cone(block: _MappedCone) -> tuple[Callable[[int], Cone], np.ndarray]:
    """The fccqp cone of a mapped block (given its start in ``v``) and its column order."""
    if block.rows.shape[0] == 3:
        mu = float(block.alpha[0] / abs(block.alpha[1]))
        return partial(FrictionCone, mu=mu), block.cols[[1, 2, 0]]
    return partial(SecondOrderCone, dim=int(block.rows.shape[0])), block.cols


def _permutation(n: int, blocks: list[np.ndarray]) -> np.ndarray:
    """Column order keeping free columns in place and each block contiguous at its first column."""
    block_of = np.full(n, -1)
    for k, cols in enumerate(blocks):
        block_of[cols] = k
    order: list[int] = []
    emitted = np.zeros(len(blocks), dtype=bool)
    for j in range(n):
        k = block_of[j]
        if k < 0:
            order.append(j)
        elif not emitted[k]:
            order.extend(int(c) for c in blocks[k])
            emitted[k] = True
    return np.asarray(order, dtype=np.int64)


def _merge_bounds(
    rows: np.ndarray, cols: np.ndarray, vals: np.ndarray, b: np.ndarray, n: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Merge simple bound rows per column.

    Returns the tightest ``lb``, ``ub`` per column of ``x``, the rows that define them
    (``-1`` where none) as ``(lower_row, upper_row)``.
    """
    lb, ub = np.full(n, -np.inf), np.full(n, np.inf)
    lower_row, upper_row = np.full(n, -1), np.full(n, -1)
    for row, col, a in zip(rows, cols, vals, strict=True):
        bound = b[row] / a
        if a > 0 and bound < ub[col]:
            ub[col], upper_row[col] = bound, row
        elif a < 0 and bound > lb[col]:
            lb[col], lower_row[col] = bound, row
    return lb, ub, lower_row, upper_row


def translate(
    P: sp.sparray | None, c: np.ndarray, A: sp.sparray, b: np.ndarray, dims: ConeDims,
    lower: np.ndarray | None = None, upper: np.ndarray | None = None,
) -> Translation:
    """Translate CVXPY's ``min 1/2 x'Px + c'x, A x + s = b, s in K`` to fccqp's form.

    Parameters
    ----------
    P : (n, n) sparse matrix or None
        Symmetric cost matrix (both triangles), ``None`` for a linear objective.
    c : (n,) array
        Linear cost.
    A : (m, n) sparse matrix
        Constraint matrix, rows ordered zero, nonnegative, then second-order blocks.
    b : (m,) array
        Right-hand side.
    dims : ConeDims
        Sizes of the cone blocks.
    lower, upper : (n,) arrays, optional
        Variable bounds CVXPY passes to solvers with ``BOUNDED_VARIABLES``
        (``cp.Variable(bounds=...)``, ``nonneg=True``); ``None`` for none. They join
        the box directly; a column with a finite variable bound is never part of a
        native cone (fccqp allows no bound on a cone entry), so such a block gets
        slacks.

    Returns
    -------
    Translation
        The fccqp problem and the index maps back to CVXPY's variables and duals;
        see the module docstring for the rules.
    """
    c = np.asarray(c, dtype=np.float64).reshape(-1)
    b = np.asarray(b, dtype=np.float64).reshape(-1)
    n, m = c.shape[0], b.shape[0]
    A = sp.csr_array(A, dtype=np.float64, copy=True)
    A.eliminate_zeros()
    A.sort_indices()
    counts, cols, vals = _single_entries(A)
    var_lb = np.full(n, -np.inf) if lower is None else np.asarray(lower, np.float64).reshape(-1)
    var_ub = np.full(n, np.inf) if upper is None else np.asarray(upper, np.float64).reshape(-1)
    var_bounded = np.isfinite(var_lb) | np.isfinite(var_ub)

    used = np.zeros(n, dtype=bool)
    mapped: list[_MappedCone] = []
    slack_soc: list[np.ndarray] = []
    offset = dims.zero + dims.nonneg
    for dim in dims.soc:
        rows = np.arange(offset, offset + dim)
        offset += dim
        block = _mappable_cone(rows, counts, cols, vals, b, used | var_bounded)
        if block is None:
            slack_soc.append(rows)
        else:
            used[block.cols] = True
            mapped.append(block)

    nonneg = np.arange(dims.zero, dims.zero + dims.nonneg)
    simple = nonneg[(counts[nonneg] == 1) & ~used[cols[nonneg]]]
    lb_x, ub_x, lower_row, upper_row = _merge_bounds(simple, cols[simple], vals[simple], b, n)
    # Bound rows that cross each other or the variable bounds stay general rows.
    crossed = np.maximum(lb_x, var_lb) > np.minimum(ub_x, var_ub)
    lb_x[crossed], ub_x[crossed] = -np.inf, np.inf
    lower_row[crossed] = upper_row[crossed] = -1
    # A strictly tighter variable bound replaces the row's (its dual is not CVXPY's to
    # report); on a tie the row keeps it, so that the row's dual is returned.
    lower_row[var_lb > lb_x] = -1
    upper_row[var_ub < ub_x] = -1
    lb_x, ub_x = np.maximum(lb_x, var_lb), np.minimum(ub_x, var_ub)
    simple = simple[~crossed[cols[simple]]]
    slack_nonneg = np.setdiff1d(nonneg, simple, assume_unique=True)

    native = [_native_cone(block) for block in mapped]
    perm = _permutation(n, [order for _, order in native])
    position = np.empty(n, dtype=np.int64)
    position[perm] = np.arange(n)
    cones: list[Cone] = sorted(
        (make(int(position[order[0]])) for make, order in native), key=lambda c: c.start
    )

    slack_rows = np.concatenate([slack_nonneg, *slack_soc]).astype(np.int64)
    num_slacks = slack_rows.shape[0]
    N = n + num_slacks
    P_v = np.zeros((N, N))
    if P is not None:
        P_v[:n, :n] = sp.csr_array(P).toarray()[np.ix_(perm, perm)]
    q_v = np.concatenate([c[perm], np.zeros(num_slacks)])

    y_rows = np.concatenate([np.arange(dims.zero), slack_rows]).astype(np.int64)
    A_v = np.zeros((y_rows.shape[0], N))
    A_v[:, :n] = A[y_rows].toarray()[:, perm]
    A_v[dims.zero + np.arange(num_slacks), n + np.arange(num_slacks)] = 1.0
    b_v = b[y_rows].copy()

    lb_v = np.concatenate([lb_x[perm], np.full(num_slacks, -np.inf)])
    ub_v = np.concatenate([ub_x[perm], np.full(num_slacks, np.inf)])
    lb_v[n:n + slack_nonneg.shape[0]] = 0.0
    start = n + slack_nonneg.shape[0]
    for rows in slack_soc:
        cones.append(SecondOrderCone(start, int(rows.shape[0])))
        start += rows.shape[0]

    cone_rows = np.concatenate([blk.rows for blk in mapped] or [np.zeros(0, np.int64)])
    cone_cols = np.concatenate([blk.cols for blk in mapped] or [np.zeros(0, np.int64)])
    cone_alpha = np.concatenate([blk.alpha for blk in mapped] or [np.zeros(0)])
    has_lower, has_upper = lower_row >= 0, upper_row >= 0
    bound_cols = np.concatenate([np.flatnonzero(has_upper), np.flatnonzero(has_lower)])
    bound_rows = np.concatenate([upper_row[has_upper], lower_row[has_lower]]).astype(np.int64)
    return Translation(
        P=P_v, q=q_v, A=A_v, b=b_v, lb=lb_v, ub=ub_v, cones=tuple(cones),
        perm=perm, num_rows=m, y_rows=y_rows,
        cone_rows=cone_rows.astype(np.int64), cone_vars=position[cone_cols],
        cone_scale=-1.0 / cone_alpha,
        bound_rows=bound_rows, bound_vars=position[bound_cols],
        bound_scale=1.0 / vals[bound_rows],
        bound_side=np.concatenate(
            [np.ones(int(has_upper.sum())), -np.ones(int(has_lower.sum()))]
        ),
    )


def recover_primal(translation: Translation, v: np.ndarray) -> np.ndarray:
    """CVXPY's ``x`` from fccqp's ``v``: undo the permutation, drop the slacks."""
    x = np.empty(translation.perm.shape[0])
    x[translation.perm] = v[: translation.perm.shape[0]]
    return x


def recover_duals(translation: Translation, y: np.ndarray, z: np.ndarray) -> np.ndarray:
    """CVXPY's stacked dual vector from fccqp's multipliers.

    Parameters
    ----------
    translation : Translation
        The translation the solve used.
    y : array
        fccqp's multipliers of ``A_f v = b_f``.
    z : array
        fccqp's box and cone multipliers (one per entry of ``v``).

    Returns
    -------
    (m,) array
        Duals in CVXPY's row order with ``P x + c + A'z = 0``, ``z in K*``; second-order
        blocks are ``[t, v...]`` as CVXPY's ``extract_dual_value`` expects. A mapped
        bound row gets its entry's box multiplier only while that bound is the active
        side (``z > 0`` upper, ``z < 0`` lower); otherwise 0.
    """
    t = translation
    duals = np.zeros(t.num_rows)
    duals[t.y_rows] = y
    duals[t.cone_rows] = z[t.cone_vars] * t.cone_scale
    box = z[t.bound_vars]
    duals[t.bound_rows] = np.where(t.bound_side * box > 0, box * t.bound_scale, 0.0)
    return duals
