"""Certificates for runs that stalled, from two auxiliary QPs of fccqp's own class.

ADMM's successive differences reach an infeasibility certificate only like ``1/k``
where the certificate set is thin (a tilted friction cone beside a boxed entry, cones
pinned outside their sum by a gap of 1e-4: 4000 iterations and the cleaning of
:func:`fccqp.certificates.clean_primal_certificate` left them uncertified). When a run
ends at ``MAX_ITER_REACHED`` untimed, or with ``AUXILIARY_TIME`` seconds of its time
limit left (never in a control tick), :class:`fccqp.Solver` asks for a certificate
directly, within the time left, each by a strongly posed QP that fccqp solves (with its polish,
in a few dozen iterations on the fuzzing campaign's stalls):

- primal: the least distance between ``{x: A x = b}`` and the constraint set,
  ``min 1/2 ||x_S - u||^2`` s.t. ``A x = b`` (last, each row divided by its largest
  entry, :func:`row_norms`), ``u`` in C (the box and the cones). Its
  multipliers ``(y, z_u)`` satisfy ``A'y + E_S'z_u = 0`` and ``b'y + sigma_C(z_u) =
  -||x_S - u||^2``: a Farkas certificate whenever the distance is positive (the dual of
  the least-distance problem is the certificate problem), its separation weighed
  against what the residual explains at the nearest ``x`` (not the run's iterate, which
  may be diverging along a ray) and the box's bounds. When that certificate fails
  though the distance is positive, the distance measured against the rows' terms:
  each row whose ``b_i`` is not zero to its terms' accuracy may be missed by ``|b_i|
  r_i`` at the cost ``1/2 r_i^2``, whose multipliers maximize the separation against
  the size of ``(b_i y_i)`` and ``z_u`` together, the terms the Farkas test weighs it
  against (:func:`relative_distance_problem`);
- dual: the projection of ``-q`` onto the cone of rays, ``min 1/2 ||d||^2 + q'd`` s.t.
  ``P d = 0``, ``A d = 0``, ``d`` in the recession cone of C, which by Moreau has
  ``q'd = -||d||^2``: a ray of descent whenever it is not zero.

Neither is trusted as it comes: each candidate passes the tests the run's own
candidates take, on the run's scaled problem (:meth:`fccqp.admm.Workspace.judge_certificate`),
or the run keeps its status. On a feasible, bounded problem the distance and the
projection are zero, and what the auxiliary solves return does not separate.

ADMM's progress on a hard problem depends on the KKT form it iterates in: the full
form adds ``sigma``'s proximal term on every entry, the reduced forms iterate on the
constrained entries alone. A problem that stalls in one form often solves in the other
(the fuzzing campaign: a least-distance QP of three pinned friction cones stalled for
4000 iterations in the reduced form and solved in 30 in the full one; a feasible QP
with ``P`` of 1e-12 stalled in the full form and solved in the reduced one). So an
auxiliary solve that is not SOLVED runs again in the other form
(:func:`other_form`), then on the sparse path (:func:`_further_tries`), unless its
point certifies already (:func:`_certifying`, :func:`_ray_found`), and
:func:`solved_again` solves the stalled problem itself
again there when no certificate was found, and then, if it stalls there too, at a
larger rho, at a smaller one (fixed below the floor when the stalled run's rho sat
there), and without equilibration. A forced ``kkt_backend`` keeps its form and gets the other tries.

On the sparse path (a :attr:`fccqp.admm.Workspace.compressed` run) the auxiliary QPs
are built with ``scipy.sparse`` and take the sparse path too, whatever their size;
there is no other form to try there: an auxiliary solve that is not SOLVED runs again
without equilibration (:func:`_further_tries`), and the other tries stay on the sparse
path.
"""

from __future__ import annotations

import dataclasses
import math
import time

import numpy as np
import scipy.sparse as sp

from fccqp.cones import cone_tuple
from fccqp.problem import INFINITE_BOUND
from fccqp.settings import MAX_DENSE_KKT_ROWS
from fccqp.status import Status
from fccqp.tuning import (
    AUXILIARY_MARGIN,
    EQUALITY_MISSED,
    RHO_MIN,
    STALL_RHO_FACTOR,
    WEAK_SEPARATION,
)

UNTIMED = math.inf
"""The deadline of an untimed run's auxiliary solves (none)."""


def _matrix(matrix: object, rows: int, n: int, sparse: bool) -> object:
    """``matrix`` (None: zeros) as a ``rows x n`` float64 array, or CSC matrix when
    ``sparse``."""
    if sparse:
        return sp.csc_matrix((rows, n)) if matrix is None else sp.csc_matrix(
            matrix, dtype=np.float64)
    if matrix is None:
        return np.zeros((rows, n))
    return np.asarray(matrix, dtype=np.float64).reshape(rows, n)


def _bounds(lb: object, ub: object, n: int) -> tuple[np.ndarray, np.ndarray]:
    """The bounds with ``None`` and entries beyond ``INFINITE_BOUND`` as infinite."""
    low = np.full(n, -np.inf) if lb is None else np.array(lb, dtype=np.float64).reshape(n)
    high = np.full(n, np.inf) if ub is None else np.array(ub, dtype=np.float64).reshape(n)
    low[low <= -INFINITE_BOUND] = -np.inf
    high[high >= INFINITE_BOUND] = np.inf
    return low, high


def distance_problem(A: object, b: np.ndarray, lb: np.ndarray, ub: np.ndarray,
                     cones: tuple) -> tuple[tuple, np.ndarray]:
    """The least-distance QP in the variables ``(x, u)``, ``u`` a copy of the
    constrained entries ``S`` (in their order, so cone blocks stay contiguous), and
    ``S``; its matrices are CSC when ``A`` is."""
    n, m = A.shape[1], A.shape[0]
    member = np.zeros(n, dtype=bool)
    for cone in cones:
        member[cone.start:cone.start + cone.dim] = True
    S = np.flatnonzero(member | np.isfinite(lb) | np.isfinite(ub))
    s = S.size
    position = np.full(n, -1)
    position[S] = np.arange(s)
    if sp.issparse(A):
        E = sp.csc_matrix((np.ones(s), (np.arange(s), S)), shape=(s, n))
        P = sp.bmat([[E.T @ E, -E.T], [-E, sp.eye(s)]], format="csc")
        A_ext = sp.hstack([A, sp.csc_matrix((m, s))], format="csc")
    else:
        E = np.zeros((s, n))
        E[np.arange(s), S] = 1.0
        P = np.block([[E.T @ E, -E.T], [-E, np.eye(s)]])
        A_ext = np.hstack([A, np.zeros((m, s))])
    lb_ext = np.concatenate([np.full(n, -np.inf), lb[S]])
    ub_ext = np.concatenate([np.full(n, np.inf), ub[S]])
    moved = [dataclasses.replace(c, start=n + int(position[c.start])) for c in cones]
    return (P, np.zeros(n + s), A_ext, b, lb_ext, ub_ext, moved), S


def row_norms(A: object) -> np.ndarray:
    """The largest magnitude in each row of ``A`` (dense or CSC), 1 for a row with none.

    When the least distance in the user's rows certifies nothing, it is tried again
    with its rows divided by these: the affine set ``{x: A x = b}``, and so the
    distance, does not depend on the rows' scale, while its QP does. Rows of 1e10 to
    2e11 beside a friction cone capped through a boxed copy of its normal force
    (infeasible by 8e-4) left the least-distance QP SOLVED_INACCURATE after 4000
    iterations in every form, its multipliers 1e-14 short of its identity; divided, it
    is solved in 24 and certifies. Not first: a friction cone pinned outside itself by
    two rows, variables rescaled by 1e-8..1e8, is certified on the sparse path in the
    user's rows and not in the divided ones."""
    largest = abs(A).max(axis=1)
    largest = np.asarray(largest.toarray() if sp.issparse(largest) else largest,
                         dtype=np.float64).reshape(-1)
    return np.where(largest > 0.0, largest, 1.0)


def _divided(A: object, norms: np.ndarray) -> object:
    """``A`` with each row divided by its entry of ``norms`` (CSC stays CSC)."""
    if sp.issparse(A):
        return sp.csc_matrix(sp.diags(1.0 / norms) @ A)
    return A / norms[:, None]


def relative_distance_problem(A: object, b: np.ndarray, lb: np.ndarray, ub: np.ndarray,
                              cones: tuple, x: np.ndarray) -> tuple[tuple, np.ndarray,
                                                                    np.ndarray]:
    """The least-distance QP with the rows softened to their own size: variables
    ``(x, u, r)``, ``r`` one entry per soft row, ``min 1/2 ||x_S - u||^2 + 1/2 ||r||^2``
    s.t. ``A_i x / |b_i| - r_i = b_i / |b_i|`` on the soft rows and ``A_i x = b_i`` on
    the others, ``u`` in C; with ``S`` and the rows' divisors (``|b_i|``, 1 on the hard
    rows), by which its multipliers ``y`` are divided to be ``A``'s. A row is hard when
    ``|b_i|`` is within ``EQUALITY_MISSED`` of its terms ``sum_j |A_ij x_j|`` at ``x``
    (the plain least distance's point): zero to the accuracy the Farkas test grants,
    its ``b_i y_i`` costs nothing there (a right-hand side of 2.6e-6 beside terms of
    1e10 made a row of 6e15 soft, and the solve missed its identity).

    Its dual asks ``A'y + E_S'z_u = 0`` and the largest separation ``-(b'y +
    sigma_C(z_u))`` less ``1/2 (||z_u||^2 + sum_i (b_i y_i)^2)``: the certificate whose
    separation is largest against its terms, as the Farkas test measures them, and the
    same whatever the rows' scale. The plain least distance ignores ``y``'s size, so
    two nearly parallel rows whose terms cancel can carry its certificate, which then
    separates by less than ``SEPARATION_FLOOR`` of them (rows of 2e10 beside a capped
    friction cone: 2.3e-10 of its terms, where this one gives 1.8e-4)."""
    (P, q, A_ext, b, lb_ext, ub_ext, moved), S = distance_problem(A, b, lb, ub, cones)
    terms = abs(A) @ np.abs(x)
    hard = np.abs(b) <= EQUALITY_MISSED * np.asarray(terms).reshape(-1)
    soft = np.flatnonzero(~hard)
    divisors = np.where(hard, 1.0, np.abs(b))
    m, k = b.shape[0], soft.size
    if sp.issparse(A_ext):
        R = sp.csc_matrix((-np.ones(k), (soft, np.arange(k))), shape=(m, k))
        A_ext = sp.hstack([sp.diags(1.0 / divisors) @ A_ext, R], format="csc")
        P = sp.block_diag([P, sp.eye(k)], format="csc")
    else:
        R = np.zeros((m, k))
        R[soft, np.arange(k)] = -1.0
        A_ext = np.hstack([A_ext / divisors[:, None], R])
        P = np.block([[P, np.zeros((P.shape[0], k))], [np.zeros((k, P.shape[0])), np.eye(k)]])
    lb_ext = np.concatenate([lb_ext, np.full(k, -np.inf)])
    ub_ext = np.concatenate([ub_ext, np.full(k, np.inf)])
    return (P, np.zeros(q.shape[0] + k), A_ext, b / divisors, lb_ext, ub_ext, moved), S, divisors


def ray_problem(P: object, q: np.ndarray, A: object, lb: np.ndarray,
                ub: np.ndarray, cones: tuple) -> tuple:
    """The projection of ``-q`` onto the rays: ``P``'s nonzero rows and ``A``'s as
    equalities asking 0, each entry's bounds at 0 on their finite sides (the box's
    recession cone), the same cones; ``q`` scaled by a power of two to largest entry
    about 1 (the projection is homogeneous). Its matrices are CSC when ``P`` is."""
    n = q.shape[0]
    if sp.issparse(P):
        P = P.tocsr()
        nonzero = np.flatnonzero(abs(P).max(axis=1).toarray().reshape(-1) > 0)
        rows = sp.vstack([P[nonzero], A], format="csc")
        identity = sp.eye(n, format="csc")
    else:
        rows = np.vstack([P[np.abs(P).max(axis=1, initial=0.0) > 0], A])
        identity = np.eye(n)
    largest = float(np.abs(q).max(initial=0.0))
    q = q * 2.0 ** -math.frexp(largest)[1] if largest > 0 else q
    low = np.where(np.isfinite(lb), 0.0, -np.inf)
    high = np.where(np.isfinite(ub), 0.0, np.inf)
    return (identity, q, rows, np.zeros(rows.shape[0]), low, high, list(cones))


def _affordable(problem: tuple) -> bool:
    """Whether an auxiliary problem may be solved: any sparse one (it takes the sparse
    path), a dense one while it stays on the dense path (its KKT matrix has up to
    twice the rows of the run's: on the sparse path it would cost far more)."""
    return (sp.issparse(problem[0])
            or problem[0].shape[0] + problem[2].shape[0] <= MAX_DENSE_KKT_ROWS)


IDENTITY = 1e-3
"""The auxiliary solution must meet its identity (``b'y + sigma_C(z_u) = -||x_S - u||^2``,
``q'd = -||d||^2``) to this fraction of ``||.||^2``: a point within the auxiliary solve's
tolerance of a zero solution (a feasible or bounded problem) does not, whatever its
residuals. Without it, on Maros-Meszaros QE226 (which has an optimum) a ray solve's
``d`` of 1e-5 with ``q'd`` of -0.87 ``|q||d|`` passed the dual tests."""


def _least_distance(result: object, b: np.ndarray, low: np.ndarray, high: np.ndarray,
                    n: int) -> bool:
    """Whether the least-distance solve (``b`` its own right-hand side) ended SOLVED,
    finite, at a positive distance that its multipliers' separation equals (duality):
    on QSCORPIO (Maros-Meszaros, an optimum) the solve itself ended PRIMAL_INFEASIBLE
    on rounding noise, and its ``y`` passed the Farkas tests. The distance counts the
    rows' misses ``r`` of :func:`relative_distance_problem` (the entries after ``u``)."""
    if result.status is not Status.SOLVED:
        return False
    if not (np.all(np.isfinite(result.x)) and np.all(np.isfinite(result.y))
            and np.all(np.isfinite(result.z))):
        return False
    s = low.shape[0]
    w = result.z[n:n + s]
    misses = result.x[n + s:]
    distance = float(w @ w) + float(misses @ misses)
    up, down = np.maximum(w, 0.0), np.minimum(w, 0.0)
    support = float(np.where(np.isfinite(high), high, 0.0) @ up
                    + np.where(np.isfinite(low), low, 0.0) @ down)
    separation = float(b @ result.y) + support
    return distance > 0.0 and abs(separation + distance) <= IDENTITY * distance


def _at_positive_distance(result: object, n: int) -> bool:
    """Whether a least-distance solve ended SOLVED, finite, at a positive distance
    (multipliers ``x_S - u`` not all zero): then a failed certificate may be the
    tolerance's doing, not the problem's. The solve stops when its residuals meet
    ``eps_abs`` and ``eps_rel``, which say nothing of the identity of
    :func:`_least_distance` when the distance itself is within a few tolerances: a
    friction cone in units of 1e-2 pinned outside itself by 1e-3 of its size (6e-6 in
    all) met it in the reduced form and not in the full one (fuzz extreme_data:900343),
    and a distance of 1.3e-4 (13 times ``eps_abs``) left the identity off by more than
    ``IDENTITY`` in the reduced forms after 40 iterations, met in 110 more at the Farkas
    tolerances (primal_infeasible 1700289; 1700339 alike). Solved again to the Farkas
    test, as a least-distance solution whose certificate fails."""
    return (result.status is Status.SOLVED and bool(np.all(np.isfinite(result.z)))
            and float(np.abs(result.z[n:]).max(initial=0.0)) > 0.0)


def _moreau(d: np.ndarray, q: np.ndarray) -> bool:
    """Whether ``d`` is finite, nonzero and meets ``q'd = -||d||^2``, as the projection of
    ``-q`` onto the rays does."""
    if not np.all(np.isfinite(d)):
        return False
    norm = float(d @ d)
    return norm > 0.0 and abs(float(q @ d) + norm) <= IDENTITY * norm


def other_form(settings: object, backend: str) -> object:
    """``settings`` for a solve in the KKT form other than ``backend`` (the form a run
    ended in, :attr:`fccqp.Result.backend`): the reduced forms (Schur first, with its
    own fallback to LDL') after the full one, the full one after a reduced one."""
    return settings.replace(kkt_backend="schur_reduced" if backend == "ldl_full"
                            else "ldl_full")


def _auxiliary_solver(solver_type: type, settings: object, deadline: float) -> object:
    """A ``solver_type`` with ``settings``, no log nor warm start, that asks for no
    certificate of its own, and whose time limit is what is left until ``deadline``
    (a ``time.perf_counter`` instant; :data:`UNTIMED` for none): the auxiliary solves of
    a timed run share the run's own budget."""
    left = max(deadline - time.perf_counter(), 0.0)
    solver = solver_type(settings.replace(verbose=False, warm_start=False,
                                          time_limit=min(settings.time_limit, left)))
    solver._stalled_certificates = False
    return solver


def _is_solved(result: object) -> bool:
    """Whether an auxiliary solve ended SOLVED."""
    return result.status is Status.SOLVED


def _further_tries(settings: object, backend: str) -> list:
    """``settings`` for solving an auxiliary problem again, in order, after a solve in
    ``backend`` gave no usable result: on the dense path the other form
    (:func:`other_form`), then the sparse path; on the sparse path, which has one form,
    no equilibration (nothing when ``settings`` has none already).

    The least-distance QP of a friction cone capped through a boxed copy of its
    normal force, beside two nearly parallel rows of 2e10, crawls in the full form
    once equilibrated (rho at its floor, 20000 iterations on the sparse path, never
    polished; ``ldl_full`` alike), where the reduced form solves it in 40 iterations;
    in the user's units the full form's final polish solves it (``ldl_full`` in 250
    iterations, the sparse path at its 4000), and its certificate passes. The
    projection onto the rays of a second-order cone beside a box entry whose recession
    cone pins it, in a null space of ``P`` and ``A`` of dimension 5 (``P``'s rows of
    rank 9 with four singular values of 1e-14), has multipliers 5000 times the ray:
    ADMM crawls in both dense forms (4000 iterations, the box missed by 4e-5, a cone
    block 1e-2 off its apex), and the dense polish, regularized as the dense forms
    are, puts that block on its boundary at 1e-11 where the multipliers ask its apex;
    the sparse path's polish (qdldl, its own regularization) finds the apex, SOLVED
    in 170 iterations."""
    if backend != "sparse":
        return [other_form(settings, backend), settings.replace(kkt_backend="sparse")]
    return [settings.replace(scaling=0)] if settings.scaling else []


def _solved(solver_type: type, settings: object, problem: tuple, deadline: float,
            usable: object = _is_solved) -> tuple:
    """``(result, iterations, factorizations)`` of an auxiliary ``problem``: solved with
    ``settings`` by ``deadline``, and again (:func:`_further_tries`, in turn) until a
    result is ``usable`` (by default: SOLVED); the counts are those of every solve."""
    result = _auxiliary_solver(solver_type, settings, deadline).solve(*problem)
    spent, factored = result.iterations, result.factorizations
    tries = [] if usable(result) else _further_tries(settings, result.backend)
    for again_settings in tries:
        result = _auxiliary_solver(solver_type, again_settings, deadline).solve(*problem)
        spent, factored = spent + result.iterations, factored + result.factorizations
        if usable(result):
            break
    return result, spent, factored


ANSWERS = (Status.SOLVED, Status.SOLVED_INACCURATE, Status.PRIMAL_INFEASIBLE,
           Status.DUAL_INFEASIBLE)
"""The statuses of :func:`solved_again` that replace a stalled run's: an answer,
each with the guarantees of its status."""


def solved_again(solver_type: type, settings: object, stalled: object,
                 arguments: tuple, switch_form: bool,
                 deadline: float = UNTIMED) -> object | None:
    """The problem of ``arguments`` (``P, q, A, b, lb, ub, cones``), on which a run in
    ``stalled.backend``'s form stalled, solved cold in the other form
    (:func:`other_form`, with ``switch_form``: when the form was fccqp's choice), or
    else cold at ``STALL_RHO_FACTOR`` times ``settings.rho``, at ``settings.rho /
    STALL_RHO_FACTOR`` (at a fixed rho below its floor when the run ended there), or
    without equilibration, the first of these
    that gives an answer (:data:`ANSWERS`), with the iterations and factorizations of
    the solves it took; else None. The tries share the time left until ``deadline``
    (:func:`_auxiliary_solver`) and stop when it has passed. Without ``switch_form`` every try keeps
    ``settings.kkt_backend`` (a forced backend, the sparse path): rho and the scaling
    are fccqp's to choose, the form then is not.

    The larger rho: on problems with a singular ``P`` (qpsolvers' form, ``P`` of
    1e-128) ADMM ran thousands of iterations with constant residuals while a
    multiplier grew by a fixed step, and the rho rule, which balances the two
    residuals, saw nothing to change; such a phase lasts about ``1 / rho`` iterations
    (the fuzz cases qpsolvers 500077, 500090, 700127 and extreme_data 500215, 500351:
    4000 iterations stalled in both forms, 40 to 1220 from ``rho`` = 100).

    The smaller rho: a run whose rule climbed from ``settings.rho`` to where one
    residual crawls starts the rule from ``STALL_RHO_FACTOR`` below it instead
    (variables rescaled by 1e-8..1e8 beside equality rows of entries 1e-8..1e9: rho
    rose to 16, where the dual residual of 1e14 against a tolerance of 8e3 fell by 1 %
    per 25 iterations, and 40,000 iterations in the full form did not end it; from
    1e-4 every form is SOLVED in about 540).
    Where the stalled run ended with rho at its floor (``RHO_MIN``,
    within the rule's ``adaptive_rho_tolerance``), the balance of the residuals asked
    for less: multipliers 1e-8 of the scaled primal (``P`` of 1e10 with the optimum in
    its near-null space and the cost normalized by ``P``; ``P`` of 1e-11 with the
    optimum at 5e9). At the floor ADMM crawls, in the full form ``sigma`` alike; the
    last try fixes rho and ``sigma`` at ``RHO_MIN / STALL_RHO_FACTOR`` (extreme_data 212
    and 473: 4000 iterations stalled in every form, 30 to 600 at 1e-9). A smaller
    ``sigma`` can make the convexity test fail on a ``P`` that is semidefinite to
    rounding: that try then gives no answer.

    Without equilibration, last: with ``P`` huge the cost normalization sits at its cap
    (``c`` = 1e-4) and a cone block shares one column scale between entries that ``P``
    weighs at 1e14 and entries it does not touch, so the scaled problem puts the
    optimum 1e6 from the origin while its cost pulls at 1e-7; ADMM crawls there in
    every form and at every rho (extreme_data:1300030: `|x_s|` 3e-2 of the 2e6 it must
    reach after 4000 iterations, rho at 3.7e-3). On the user's own units rho climbs to
    7e5 and the run ends in 327 iterations (SOLVED); a friction cone capped through a
    boxed copy of its normal force, variables rescaled by 1e-8..1e8
    (extreme_data:1500043), is certified infeasible in 520."""
    spent = factored = 0
    tries = [other_form(settings, stalled.backend)] if switch_form else []
    tries.append(settings.replace(rho=settings.rho * STALL_RHO_FACTOR))
    if stalled.rho < RHO_MIN * settings.adaptive_rho_tolerance:
        floor = RHO_MIN / STALL_RHO_FACTOR
        tries.append(settings.replace(rho=floor, sigma=min(settings.sigma, floor),
                                      adaptive_rho=False))
    else:
        tries.append(settings.replace(rho=settings.rho / STALL_RHO_FACTOR))
    tries.append(settings.replace(scaling=0))
    for again in tries:
        if time.perf_counter() >= deadline:
            break
        solver = _auxiliary_solver(solver_type, again, deadline)
        try:
            result = solver.solve(*arguments)
        except ValueError:   # "not convex" under the smaller sigma: no answer there
            continue
        spent, factored = spent + result.iterations, factored + result.factorizations
        if result.status in ANSWERS and not _doubted(solver, result):
            return dataclasses.replace(result, iterations=spent, factorizations=factored)
    return None


def _doubted(solver: object, result: object) -> bool:
    """Whether ``result``, ``solver``'s last answer, is a solved point on tolerances
    that its entries' own units do not give it (:attr:`fccqp.admm.Workspace.doubt`),
    whose second opinion an auxiliary solver does not ask: such a point is no answer
    for a stalled run (the fuzzer's extreme_data:1700359 on the sparse path, variables
    rescaled 1e-8..1e8: SOLVED unequilibrated where the construction is infeasible)."""
    if result.status not in (Status.SOLVED, Status.SOLVED_INACCURATE):
        return False
    workspace = solver._sparse[1] if result.backend == "sparse" else solver._workspace
    return bool(workspace.doubt)


def weakly_separated(result: object, b: np.ndarray, lb: np.ndarray,
                     ub: np.ndarray) -> bool:
    """Whether ``result``'s primal certificate ``(dy, dz)`` separates by less than
    ``WEAK_SEPARATION`` of its terms: ``-(b'dy + sigma(dz))`` against ``|b||dy|`` plus
    the box's ``|bound||dz|`` (cone entries, whose bounds are infinite, add nothing to
    either). Rows of 1e-8 to 3e7 beside a constructed optimum gave a certificate that
    passes every relative test at 2.7e-8 of its terms (fuzz extreme_data:1300300)."""
    m = b.size
    dy, dz = result.certificate[:m], result.certificate[m:]
    bound = np.where(dz > 0, ub, np.where(dz < 0, lb, 0.0))
    box = np.isfinite(bound) & (dz != 0)
    support = float(b @ dy) + float(bound[box] @ dz[box])
    size = float(np.abs(b * dy).sum()) + float(np.abs(bound[box] * dz[box]).sum())
    return not -support > WEAK_SEPARATION * size


def solved_in_other_form(solver_type: type, settings: object, claimed: object,
                         arguments: tuple, deadline: float = UNTIMED) -> object | None:
    """The problem of ``arguments`` (``P, q, A, b, lb, ub, cones``) solved cold in the
    KKT form other than ``claimed.backend``'s (:func:`other_form`, by ``deadline``) when
    that solve reaches ``SOLVED``, with the iterations and factorizations of both; else None.
    A second opinion on a weak infeasibility claim (:func:`weakly_separated`): a point
    that meets the tolerances where the certificate lies at the data's rounding."""
    result = _auxiliary_solver(solver_type, other_form(settings, claimed.backend),
                               deadline).solve(*arguments)
    if result.status is not Status.SOLVED:
        return None
    return dataclasses.replace(result, iterations=claimed.iterations + result.iterations,
                               factorizations=claimed.factorizations
                               + result.factorizations)


def _farkas(workspace: object, result: object, b: np.ndarray, lb: np.ndarray,
            ub: np.ndarray, S: np.ndarray, divisors: np.ndarray) -> np.ndarray | None:
    """The Farkas certificate of a least-distance ``result`` as ``workspace`` judges it
    (:meth:`fccqp.admm.Workspace.judge_certificate`), or None when the solution does not
    meet its identity (:func:`_least_distance`) or the certificate fails; the solve's
    rows are ``A``'s divided by ``divisors``, its ``y`` multiplied by them."""
    n, m = lb.shape[0], b.shape[0]
    if not _least_distance(result, b / divisors, lb[S], ub[S], n):
        return None
    candidate = np.zeros(m + n)
    candidate[:m] = result.y / divisors
    candidate[m + S] = result.z[n:n + S.size]
    return workspace.judge_certificate(candidate, True, np.ascontiguousarray(result.x[:n]))


def _certifying(workspace: object, b: np.ndarray, lb: np.ndarray, ub: np.ndarray,
                S: np.ndarray, divisors: np.ndarray) -> object:
    """Whether a least-distance result gives a certificate (:func:`_farkas`).

    A solve SOLVED at the Farkas tolerances can still miss the identity of
    :func:`_least_distance`: those tolerances bound its residuals, not its error along a
    direction the KKT matrix barely sees. A friction cone pinned outside itself by two
    rows, in units of 1e-2, polished in the full form to a KKT residual of 2e-15 (its
    refinement uncovering a curvature of 1.5e-13) with ``x_S - u`` of 3e-9 on two boxed
    entries where the optimum has 1e-14: against bounds of 0.08 their support and ``b'y``
    (2.3e-10 each) cancelled to miss the distance of 2.25e-11 by 1.2 %; the reduced
    form's Schur complement solve met it to 5e-8."""
    def certifies(result: object) -> bool:
        return _farkas(workspace, result, b, lb, ub, S, divisors) is not None
    return certifies


def _ray(workspace: object, result: object, q: np.ndarray) -> np.ndarray | None:
    """The dual certificate of a ray solve's ``result`` (``q`` its own cost) as
    ``workspace`` judges it, or None when its point does not meet the identity of
    :func:`_moreau` or the certificate fails."""
    if not _moreau(result.x, q):
        return None
    return workspace.judge_certificate(np.ascontiguousarray(result.x), False)


def _ray_found(workspace: object, q: np.ndarray) -> object:
    """Whether a ray solve's result ends the search for its certificate: SOLVED, or
    unsolved with a point that certifies (:func:`_ray`).

    The projection onto the rays of rows of 1e17 (a ``P`` that huge, PSD to its
    rounding) beside rows of 0.1 meets no tolerance in any form, yet its point after
    4000 iterations is the ray, a free entry that ``P`` and ``A`` do not touch. On the
    sparse path the next try, without equilibration, moved off it (``P d`` of 1e16)
    and, as the last result, was the one judged: no certificate."""
    def found(result: object) -> bool:
        return _is_solved(result) or _ray(workspace, result, q) is not None
    return found


def _farkas_tolerances(settings: object, w: np.ndarray) -> object:
    """``settings`` whose termination meets the Farkas test of a least-distance solution
    with multipliers ``w``: its dual residual, ``A'y + z``, within ``eps_prim_inf``
    (relative) of their size, ``AUXILIARY_MARGIN`` times over."""
    eps = settings.eps_prim_inf / AUXILIARY_MARGIN
    return settings.replace(eps_rel=eps, eps_abs=eps * float(np.abs(w).max()))


def _distance_certificate(solver_type: type, settings: object, workspace: object,
                          problem: tuple, S: np.ndarray, divisors: np.ndarray,
                          b: np.ndarray, lb: np.ndarray, ub: np.ndarray,
                          deadline: float) -> tuple:
    """``(certificate or None, first, iterations, factorizations)`` of a least-distance
    ``problem`` (:func:`distance_problem`, :func:`relative_distance_problem`: its rows
    ``A``'s divided by ``divisors``), judged by ``workspace`` (:func:`_farkas`);
    ``first`` is the result of its first solve."""
    n = lb.shape[0]
    first, spent, factored = _solved(solver_type, settings, problem, deadline)
    found = _farkas(workspace, first, b, lb, ub, S, divisors)
    if found is None and _at_positive_distance(first, n):
        # its multipliers have the size of the distance, and the run's tolerances left
        # them a residual of 2e-6 of it where the Farkas test allows eps_prim_inf =
        # 1e-6, or left the identity unmet: solved again to that test, and in the other
        # form where its solution still misses it (see _certifying)
        result, iterations, factorizations = _solved(
            solver_type, _farkas_tolerances(settings, first.z[n:]), problem, deadline,
            _certifying(workspace, b, lb, ub, S, divisors))
        spent, factored = spent + iterations, factored + factorizations
        found = _farkas(workspace, result, b, lb, ub, S, divisors)
    return found, first, spent, factored


def stalled_certificate(solver_type: type, settings: object, workspace: object,
                        P: object, q: object, A: object, b: object, lb: object,
                        ub: object, cones: object, primal: bool = True,
                        dual: bool = True, deadline: float = UNTIMED) -> tuple | None:
    """``(status, certificate, iterations, factorizations)`` for a run that stalled on
    this problem in ``workspace`` (or whose point passed on lent tolerances,
    :attr:`fccqp.admm.Workspace.doubt`), or None: with ``primal``, the primal
    certificate of the least distance (when there are rows and constrained entries),
    else with ``dual`` the dual one of the projection onto the rays, each judged by
    ``workspace`` (sparse QPs when it holds compressed columns). The auxiliary solves use
    ``settings`` in a ``solver_type`` (:func:`_auxiliary_solver`) by ``deadline``, in
    other forms when the first did not solve them (:func:`_solved`)."""
    q = np.asarray(q, dtype=np.float64).reshape(-1)
    n = q.shape[0]
    sparse = workspace.compressed
    P = _matrix(P, n, n, sparse)
    b = np.zeros(0) if b is None else np.asarray(b, dtype=np.float64).reshape(-1)
    A = _matrix(A, b.shape[0], n, sparse)
    m = b.shape[0]
    lb, ub = _bounds(lb, ub, n)
    cones = cone_tuple(cones or ())
    spent = factored = 0
    try:
        if primal and m > 0:
            problem, S = distance_problem(A, b, lb, ub, cones)
            if S.size and _affordable(problem):
                found, nearest, spent, factored = _distance_certificate(
                    solver_type, settings, workspace, problem, S, np.ones(m), b, lb, ub,
                    deadline)
                if found is None and _at_positive_distance(nearest, n):
                    relative, S, divisors = relative_distance_problem(
                        A, b, lb, ub, cones, nearest.x[:n])
                    softened = relative[0].shape[0] > problem[0].shape[0]
                    if softened and _affordable(relative):
                        found, _, iterations, factorizations = _distance_certificate(
                            solver_type, settings, workspace, relative, S, divisors, b,
                            lb, ub, deadline)
                        spent, factored = spent + iterations, factored + factorizations
                norms = row_norms(A)
                if found is None and np.any(norms != 1.0):
                    divided, S = distance_problem(_divided(A, norms), b / norms, lb, ub,
                                                  cones)
                    found, _, iterations, factorizations = _distance_certificate(
                        solver_type, settings, workspace, divided, S, norms, b, lb, ub,
                        deadline)
                    spent, factored = spent + iterations, factored + factorizations
                if found is not None:
                    return Status.PRIMAL_INFEASIBLE, found, spent, factored
        if not dual:
            return None
        rays = ray_problem(P, q, A, lb, ub, cones)
        if not np.any(q) or not _affordable(rays):
            return None
        result, iterations, factorizations = _solved(solver_type, settings, rays, deadline,
                                                     _ray_found(workspace, rays[1]))
        spent, factored = spent + iterations, factored + factorizations
        found = _ray(workspace, result, rays[1])
        if found is None:
            return None
        return Status.DUAL_INFEASIBLE, found, spent, factored
    except (ValueError, TypeError):   # an auxiliary problem fccqp refuses: no claim
        return None
