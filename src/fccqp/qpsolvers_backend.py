"""fccqp as a qpsolvers backend: ``qpsolvers.solve_qp(..., solver="fccqp")``.

qpsolvers poses ``min 1/2 x'Px + q'x  s.t.  G x <= h, A x = b, lb <= x <= ub``.
fccqp has no general inequalities, only equalities, a box and cones, so each row of
``G`` gets a slack variable ``s_i = G_i x`` with the upper bound ``s_i <= h_i``::

    min  1/2 x'Px + q'x          over  v = [x; s]
    s.t. [A  0] [x]   [b]
         [G -I] [s] = [0],       [lb; -inf] <= [x; s] <= [ub; h]

The equalities, ``G x = s`` included, hold to factorization accuracy at every
iterate, and every inequality becomes a box bound, which ADMM handles by a clamp.
The cost is size: ``m_G`` more variables and ``m_G`` more equality rows, so the
dense KKT matrix grows from ``n + m_A`` to ``n + m_A + 2 m_G`` rows, and the
factorization cost with its cube.

Row scale. Each row of ``G`` and ``h``, and of ``A`` and ``b``, is first multiplied by
``d_i = 1 / max_j |M_ij|`` (1 for a zero row, which keeps its meaning: ``0 <= h_i``
holds or the problem is infeasible), so that the answer does not depend on the scale
the user wrote a row in. A slack row ``[G_i, -1]`` needs it most: the slack's ``-1``
sets the row's norm, so the equilibration sees a balanced row whatever the size of
``G_i``, and a row far smaller than 1 couples ``x`` to its multiplier so weakly that
ADMM takes tens of thousands of iterations to build the multiplier up. The rows of
``A`` reach the equilibration directly, yet runs still depend on their scale (rows
times factors from 1e-4 to 1e4 took 2.5 times the iterations, at 4 Ruiz passes as at
25), so they are scaled the same way. The feasible set is unchanged (to the rounding of
the products). The multiplier of a scaled row is the user's divided by ``d_i``, so
``d_i`` multiplies it back.

Duals. fccqp returns ``(y_ext, z_ext)`` with ``P_ext v + q_ext + A_ext' y_ext +
z_ext = 0``. Its rows for ``s`` read ``-y_G + z_s = 0``, so the multiplier of
``G x <= h`` is ``z = d z_s``, the slack's box multiplier times the row scale. It
comes from the projection onto ``s <= h``, so it is zero on inactive rows and
non-negative up to rounding in the unscaling (values like ``-4.8e-18`` occur); the
backend clips it at 0, so the returned ``z`` is exactly ``>= 0``. Its rows for ``x``
then give qpsolvers' convention ``P x + q + A'y + G'z + z_box = 0`` with ``y = d
y_A`` and ``z_box = z_x``
(negative at an active lower bound, positive at an active upper bound).

fccqp's core is dense, meant for 30-300 variables: sparse ``P``, ``G``, ``A``
(``scipy.sparse`` matrices or arrays, ``csc_array`` included) are accepted and
densified. Before densifying, the size of the slack form's KKT matrix, ``n + m_A + 2
m_G`` rows, is checked against :data:`fccqp.settings.MAX_DENSE_KKT_ROWS`: a larger
problem (or any, with ``kkt_backend="sparse"``) keeps its matrices sparse, builds the
slack form sparse and takes fccqp's sparse path (``Result.backend == "sparse"``). So fccqp
is listed in both ``qpsolvers.dense_solvers`` and ``qpsolvers.sparse_solvers``.

Registration. qpsolvers has no plugin mechanism: :func:`register` adds "fccqp" to
its module-level registry, which ``import fccqp`` calls. Importing qpsolvers takes
about 60 ms (it imports every installed backend), more than fccqp may add to its
own import, so :func:`register` never imports it. If qpsolvers is already imported
the registry is updated at once; otherwise a one-shot finder on ``sys.meta_path``
updates it right after ``import qpsolvers`` finishes, then removes itself.
"""

from __future__ import annotations

import dataclasses
import importlib.util
import sys
import time
from typing import TYPE_CHECKING

import numpy as np

from fccqp._import_hooks import after_import
from fccqp.problem import issparse, validate
from fccqp.settings import MAX_DENSE_KKT_ROWS, Settings
from fccqp.status import Status

if TYPE_CHECKING:
    import scipy.sparse as sp
    from qpsolvers import Problem, Solution


SOLVER_NAME = "fccqp"
"""Name of the solver in qpsolvers' registry."""


def _settings(verbose: bool, kwargs: dict[str, object]) -> Settings:
    """Map qpsolvers keyword arguments onto :class:`fccqp.Settings`.

    Every field of ``Settings`` is a valid keyword; qpsolvers' usual names
    (``eps_abs``, ``eps_rel``, ``max_iter``, ``time_limit``) are fields already.
    """
    from qpsolvers import ParamError

    try:
        return Settings(verbose=bool(verbose)).replace(**kwargs)
    except (TypeError, ValueError) as exn:
        raise ParamError(f"fccqp: {exn}") from exn


def _kkt_rows(problem: Problem) -> int:
    """Rows of the slack form's KKT matrix, ``n + m_A + 2 m_G``, from the shapes alone."""
    def rows(M: object) -> int:
        if M is None:
            return 0
        shape = getattr(M, "shape", None) or np.shape(M)
        return shape[0] if len(shape) == 2 else 1

    return rows(problem.P) + rows(problem.A) + 2 * rows(problem.G)


def _real_array(value: object, name: str) -> np.ndarray:
    """``value`` as a float64 array; complex or non-numeric input is a ``TypeError``."""
    if issparse(value):
        value = value.toarray()
    if np.iscomplexobj(value):
        raise TypeError(f"{name} must be real, got complex entries")
    try:
        return np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exn:
        raise TypeError(f"{name} must be numeric: {exn}") from exn


def _inequalities(G: object, h: object, n: int,
                  sparse: bool = False) -> tuple[np.ndarray | sp.csc_matrix, np.ndarray]:
    """Check ``G x <= h`` and return it dense (CSC with ``sparse``); errors name ``G``
    or ``h``."""
    if sparse:
        import scipy.sparse as sp

        if np.iscomplexobj(G) or (issparse(G) and G.dtype.kind == "c"):
            raise TypeError("G must be real, got complex entries")
        G = sp.csc_matrix(G, dtype=np.float64) if issparse(G) else sp.csc_matrix(
            _real_array(G, "G"))
        values = G.data
    else:
        G = _real_array(G, "G")
        values = G
    h = _real_array(h, "h").reshape(-1)
    if G.ndim != 2 or G.shape[1] != n:
        raise ValueError(f"G must have {n} columns (the size of P), got shape {G.shape}")
    if h.shape[0] != G.shape[0]:
        raise ValueError(f"G has {G.shape[0]} rows but h has {h.shape[0]} entries")
    if not np.isfinite(values).all():
        raise ValueError("G contains NaN or inf")
    if np.isnan(h).any():
        raise ValueError("h contains NaN")
    if (h == -np.inf).any():
        i = int(np.flatnonzero(h == -np.inf)[0])
        raise ValueError(f"h[{i}] is -inf: the inequality G[{i}] x <= -inf cannot hold")
    return G, h


def _row_scales(M: np.ndarray | sp.csc_matrix, rhs: np.ndarray) -> np.ndarray:
    """``d_i = 1 / max_j |M_ij|`` for each row of ``M``.

    A zero row keeps ``d_i = 1`` (its constraint ``0 <= h_i`` or ``0 = b_i`` needs no
    scale), and so does a row whose ``d_i`` or ``d_i rhs_i`` would overflow.
    """
    if issparse(M):
        largest = abs(M).max(axis=1).toarray().reshape(-1)
    else:
        largest = np.abs(M).max(axis=1, initial=0.0)
    scales = np.ones(largest.shape[0])
    with np.errstate(divide="ignore", over="ignore"):
        np.divide(1.0, largest, out=scales, where=largest > 0)
        overflow = ~np.isfinite(scales) | (np.isfinite(rhs) & ~np.isfinite(scales * rhs))
    scales[overflow] = 1.0
    return scales


def _normalized_rows(M: np.ndarray | sp.csc_matrix, rhs: np.ndarray) -> tuple[
        np.ndarray | sp.csc_matrix, np.ndarray, np.ndarray]:
    """``(diag(d) M, d * rhs, d)`` with the row scales ``d`` of :func:`_row_scales`;
    the matrix dense or CSC like ``M``, its entries the same products either way."""
    scales = _row_scales(M, rhs)
    if issparse(M):   # CSC: entry k lies in row indices[k]
        M = M.copy()
        M.data *= scales[M.indices]
        return M, scales * rhs, scales
    return M * scales[:, None], scales * rhs, scales


def _user_certificate(result: object, n: int, scales_A: np.ndarray,
                      scales_G: np.ndarray) -> np.ndarray | None:
    """The slack form's certificate with its rows and slack entries in the user's units.

    A primal certificate ``(y, z)`` of the scaled rows is multiplied by the row scales
    on ``y`` (rows of ``A``, then the slack rows) and on the slack entries of ``z``; a
    dual certificate ``dx`` (a direction over ``[x; s]``) is divided by them on the
    slack entries.
    """
    certificate = result.certificate
    if certificate is None:
        return None
    certificate = certificate.copy()
    rows = np.concatenate([scales_A, scales_G])
    if result.status is Status.PRIMAL_INFEASIBLE:
        certificate[:rows.shape[0]] *= rows
        certificate[rows.shape[0] + n:] *= scales_G
    elif result.status is Status.DUAL_INFEASIBLE:
        certificate[n:] /= scales_G
    return certificate


def _with_slacks(data: object, G: np.ndarray | sp.csc_matrix,
                 h: np.ndarray) -> tuple[object, ...]:
    """Return ``(P, q, A, b, lb, ub)`` over ``[x; s]`` with ``G x - s = 0``, ``s <= h``;
    the matrices are dense for dense ``data`` (:class:`fccqp.problem.ProblemData`) and
    CSC for sparse ``data`` (:class:`fccqp.sparse_problem.SparseData`)."""
    n, m, k = data.n, data.m, G.shape[0]
    if issparse(data.P):
        import scipy.sparse as sp

        P = sp.block_diag([data.P, sp.csc_matrix((k, k))], format="csc")
        A = sp.vstack([sp.hstack([data.A, sp.csc_matrix((m, k))]),
                       sp.hstack([G, -sp.eye(k)])], format="csc")
    else:
        P = np.zeros((n + k, n + k))
        P[:n, :n] = data.P
        A = np.zeros((m + k, n + k))
        A[:m, :n] = data.A
        A[m:, :n] = G
        A[m:, n:] = -np.eye(k)
    return (
        P,
        np.concatenate([data.q, np.zeros(k)]),
        A,
        np.concatenate([data.b, np.zeros(k)]),
        np.concatenate([data.lb, np.full(k, -np.inf)]),
        np.concatenate([data.ub, h]),
    )


def slack_form(data: object, G: object, h: object, sparse: bool = False) -> tuple[
        tuple[object, ...], np.ndarray, np.ndarray]:
    """The problem fccqp solves for qpsolvers' ``data`` (:class:`fccqp.problem.ProblemData`,
    or :class:`fccqp.sparse_problem.SparseData` with ``sparse``) and ``G x <= h``:
    ``((P, q, A, b, lb, ub), d_A, d_G)``, the slack form of the module docstring with
    the rows of ``A, b`` and ``G, h`` multiplied by the row scales ``d_A`` and ``d_G``
    (:func:`_row_scales`). ``G`` may be None (then ``h`` too): no slacks, ``d_G``
    empty."""
    A, b, scales_A = _normalized_rows(data.A, data.b)
    data = dataclasses.replace(data, A=A, b=b)
    if G is None:
        return (data.P, data.q, data.A, data.b, data.lb, data.ub), scales_A, np.empty(0)
    G, h = _inequalities(G, h, data.n, sparse)
    G, h, scales_G = _normalized_rows(G, h)
    return _with_slacks(data, G, h), scales_A, scales_G


def _initial_guess(initvals: object, n: int) -> np.ndarray:
    if np.iscomplexobj(initvals):
        raise TypeError("initvals must be real, got complex entries")
    try:
        guess = np.asarray(initvals, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError) as exn:
        raise TypeError(f"initvals must be a numeric vector: {exn}") from exn
    if guess.shape != (n,) or not np.isfinite(guess).all():
        raise ValueError(f"initvals must be a finite vector of {n} entries, got {guess.shape}")
    return guess


def fccqp_solve_problem(
    problem: Problem,
    initvals: np.ndarray | None = None,
    verbose: bool = False,
    **kwargs: object,
) -> Solution:
    """Solve a qpsolvers ``Problem`` with fccqp.

    Parameters
    ----------
    problem : qpsolvers.Problem
        ``min 1/2 x'Px + q'x  s.t.  G x <= h, A x = b, lb <= x <= ub``. ``P`` must be
        symmetric positive semidefinite; matrices may be dense or ``scipy.sparse``
        (densified, unless the slack form's KKT matrix exceeds
        :data:`fccqp.settings.MAX_DENSE_KKT_ROWS` rows or ``kkt_backend="sparse"``:
        then the problem takes the sparse path). Inequalities become slack variables
        (see the module docstring).
    initvals : (n,) array_like, optional
        Primal initial guess ``x0``; the slacks start at their values at ``x0``.
        Without it the solve starts cold.
    verbose : bool
        Print fccqp's iteration log.
    **kwargs
        Fields of :class:`fccqp.Settings`, e.g. ``eps_abs``, ``eps_rel``, ``max_iter``,
        ``time_limit``, ``rho``.

    Returns
    -------
    qpsolvers.Solution
        ``found`` is True only for ``Status.SOLVED``. Duals follow qpsolvers:
        ``P x + q + A'y + G'z + z_box = 0`` with ``z >= 0`` exactly; absent constraint
        blocks give empty arrays. When the budget runs out, or on
        ``Status.NUMERICAL_ERROR``, ``x, y, z, z_box`` hold the last (finite) iterate
        and ``found`` is False; on infeasibility they are None. ``extras`` holds the
        fccqp ``status``, ``iterations``, ``prim_res``, ``dual_res`` (of the slack
        form with its rows scaled), ``setup_time``, ``solve_time``, ``rho``,
        ``factorizations``, ``backend`` (the KKT backend that ran, ``"sparse"`` on the
        sparse path) and ``certificate`` (of the slack form in the user's units, see
        ``fccqp.Result``).

    Raises
    ------
    qpsolvers.ParamError
        On an unknown keyword or an invalid setting value, naming it.
    ValueError, TypeError
        On malformed problem data, naming the argument (``P``, ``q``, ``G``, ``h``,
        ``A``, ``b``, ``lb``, ``ub``, ``initvals``; complex entries included), or when
        ``P`` is not convex on the null space of ``A``.
    """
    from qpsolvers import Solution

    # Through the package, not at module level: `import fccqp` registers this backend
    # and must not load the compiled core, which fccqp.Solver loads on first access
    # (with scipy's LAPACK tables, see fccqp/__init__.py).
    from fccqp import Solver

    build_start = time.perf_counter()
    problem.check_constraints()
    settings = _settings(verbose, kwargs)
    P, q, G, h, A, b, lb, ub = problem.unpack()
    sparse = settings.kkt_backend == "sparse" or _kkt_rows(problem) > MAX_DENSE_KKT_ROWS
    if sparse:   # never densified: the slack form is built sparse, for the sparse path
        from fccqp.sparse_problem import convert

        data = convert(P, q, A, b, lb, ub)
    else:
        data = validate(P, q, A, b, lb, ub)
    x0 = None if initvals is None else _initial_guess(initvals, data.n)
    args, scales_A, scales_G = slack_form(data, G, h, sparse)
    if G is not None and x0 is not None:
        x0 = np.concatenate([x0, args[2][data.m:, :data.n] @ x0])   # the scaled G x0
    solve_start = time.perf_counter()
    result = Solver(settings).solve(*args, x0=x0)
    solve_end = time.perf_counter()

    solution = Solution(problem)
    solution.found = result.status.is_solved()
    solution.extras = {
        "status": result.status,
        "iterations": result.iterations,
        "prim_res": result.prim_res,
        "dual_res": result.dual_res,
        "setup_time": result.setup_time,
        "solve_time": result.solve_time,
        "rho": result.rho,
        "factorizations": result.factorizations,
        "backend": result.backend,
        "certificate": _user_certificate(result, data.n, scales_A, scales_G),
    }
    solution.build_time = solve_start - build_start
    solution.solve_time = solve_end - solve_start
    if result.status.is_infeasible():
        return solution
    n, m_A = data.n, data.m
    solution.obj = result.obj
    solution.x = result.x[:n]
    solution.y = result.y[:m_A] * scales_A
    solution.z = np.maximum(result.z[n:], 0.0) * scales_G
    solution.z_box = result.z[:n] if lb is not None or ub is not None else np.empty(0)
    return solution


def fccqp_solve_qp(
    P: np.ndarray | sp.sparray | sp.spmatrix,
    q: np.ndarray,
    G: np.ndarray | sp.sparray | sp.spmatrix | None = None,
    h: np.ndarray | None = None,
    A: np.ndarray | sp.sparray | sp.spmatrix | None = None,
    b: np.ndarray | None = None,
    lb: np.ndarray | None = None,
    ub: np.ndarray | None = None,
    initvals: np.ndarray | None = None,
    verbose: bool = False,
    **kwargs: object,
) -> np.ndarray | None:
    """Solve ``min 1/2 x'Px + q'x  s.t.  G x <= h, A x = b, lb <= x <= ub`` with fccqp.

    The arguments are those of :func:`qpsolvers.solve_qp` (see
    :func:`fccqp_solve_problem` for ``initvals``, ``verbose`` and ``kwargs``).

    Returns
    -------
    (n,) numpy.ndarray or None
        The solution when fccqp reports ``Status.SOLVED``, otherwise None.
    """
    from qpsolvers import Problem

    problem = Problem(P, q, G, h, A, b, lb, ub)
    solution = fccqp_solve_problem(problem, initvals, verbose, **kwargs)
    return solution.x if solution.found else None


def _add_to_registry() -> bool:
    """Put fccqp in qpsolvers' registry, mutating its lists and dict in place.

    ``qpsolvers.solve_problem`` looks solvers up in ``solve_function``; the lists
    ``available_solvers``, ``dense_solvers`` and ``sparse_solvers`` are what users and
    qpsolvers' messages consult. Other modules hold these same objects, hence in place.
    """
    try:
        from qpsolvers import solvers
    except ImportError:
        return False
    for names in (solvers.available_solvers, solvers.dense_solvers, solvers.sparse_solvers):
        if SOLVER_NAME not in names:
            names.append(SOLVER_NAME)
    solvers.solve_function[SOLVER_NAME] = fccqp_solve_problem
    return True


def register() -> bool:
    """Make ``solver="fccqp"`` available in qpsolvers, without importing it.

    If qpsolvers is imported already, fccqp is added to its registry now; if it is
    installed but not imported, a one-shot import hook adds it right after
    ``import qpsolvers``. Calling this again is harmless.

    Returns
    -------
    bool
        False, having done nothing, when qpsolvers is not installed.
    """
    if "qpsolvers" not in sys.modules and importlib.util.find_spec("qpsolvers") is None:
        return False
    after_import("qpsolvers", lambda module: _add_to_registry())
    return True
