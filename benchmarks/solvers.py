"""Solver adapters: one small class per benchmarked variant, all with one interface.

Every adapter splits a solve in two: :meth:`Adapter.prepare` turns a
:class:`~benchmarks.wbc_qp.WbcQP` into the solver's own input (matrix conversion,
pyramid rows, cone lists) outside the timed region; :meth:`Adapter.solve` times the
solver's own Python call with :func:`time.perf_counter`. Adapters that warm start keep
their state between calls; :meth:`Adapter.reset` forgets it at a sequence boundary.

Every peer runs at its own default settings and with its own warm-start support:

- ``fccqp-realtime`` / ``fccqp-default``: :class:`fccqp.Solver` with
  ``Settings.realtime()`` / ``Settings()``, exact cones, warm across a sequence.
- ``clarabel``: exact second-order cones; Clarabel has no warm start and no update for
  new matrices, so ``DefaultSolver(...)`` construction and ``solve()`` are both timed.
- ``proxqp-pyr4``, ``proxqp-pyr8``: ProxQP's dense backend on the 4- or 8-facet inner
  pyramid, torque limits as its box constraints. The first QP of a sequence builds and
  ``init``-s a model; later ones ``update`` it and warm start from the previous result
  (``WARM_START_WITH_PREVIOUS_RESULT``) when the dimensions are unchanged.
- ``osqp-pyr4``, ``osqp-pyr8``: OSQP on the same pyramids; ``setup`` and ``solve`` are
  timed for every QP (the sparsity pattern changes), warm started with
  ``warm_start(x, y)`` from the previous solution of the sequence.
- ``qpsolvers:<name>``: the 4-facet pyramid through ``qpsolvers.solve_problem``, cold,
  as a one-call qpsolvers user sees it. qpsolvers has no cones, so ``qpsolvers:fccqp``
  also gets the pyramid rows ``G x <= h``.

:func:`kkt_factorization_time` is the speed yardstick: one LAPACK ``dsytrf`` of the
QP's KKT matrix.
"""

from __future__ import annotations

import importlib.util
import time
from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import sparse
from scipy.linalg import lapack

from benchmarks.wbc_qp import WbcQP, clarabel_problem

__all__ = [
    "KKT_REGULARIZATION",
    "VARIANTS",
    "Adapter",
    "SolveOutcome",
    "available_variants",
    "kkt_factorization_time",
    "make_adapter",
]

KKT_REGULARIZATION = 1e-6
"""Diagonal added to ``P`` in the baseline KKT matrix (fccqp's default ``sigma``)."""

_LWORK_PER_ROW = 64
"""dsytrf work size per row (its block size): scipy's default work size is unblocked."""


@dataclass(frozen=True)
class SolveOutcome:
    """What one timed solve returns.

    Attributes
    ----------
    x
        Primal solution (NaNs when the solver returned none).
    status
        The solver's own status string.
    success
        Whether the solver itself reports success (its "solved" status only).
    iterations
        Iterations the solver reports (-1 when it reports none).
    time
        Wall time of the timed call, in seconds.
    """

    x: np.ndarray
    status: str
    success: bool
    iterations: int
    time: float


class Adapter(ABC):
    """Common interface of the benchmarked variants.

    Attributes
    ----------
    name
        Variant name, a key of :data:`VARIANTS`.
    exact_cones
        Whether the solver sees the exact friction cones (else an inner pyramid).
    warm
        Whether solves within a sequence warm start from the previous one.
    """

    name: str
    exact_cones: bool
    warm: bool

    @abstractmethod
    def prepare(self, qp: WbcQP) -> Any:
        """Convert ``qp`` to the solver's input; not timed."""

    @abstractmethod
    def solve(self, data: Any) -> SolveOutcome:
        """Solve prepared data, timing only the solver's own call."""

    @abstractmethod
    def reset(self) -> None:
        """Forget warm-start state (called at each sequence boundary)."""


def _pyramid_rows(qp: WbcQP, facets: int) -> tuple[np.ndarray, np.ndarray]:
    return qp.pyramid(facets=facets, inner=True)


def _torque_box(qp: WbcQP) -> tuple[np.ndarray, np.ndarray]:
    """Indices and bounds of the finite bounds (the torques) as arrays."""
    idx = np.flatnonzero(np.isfinite(qp.lb) | np.isfinite(qp.ub))
    return idx, np.stack([qp.lb[idx], qp.ub[idx]])


def fccqp_arguments(qp: WbcQP) -> tuple[Any, ...]:
    """``(P, q, A, b, lb, ub, cones)`` for ``fccqp.Solver.solve``: exact friction cones."""
    import fccqp

    flat = np.array([0.0, 0.0, 1.0])
    cones = tuple(
        fccqp.FrictionCone(
            int(s), float(mu), None if np.allclose(n, flat) else tuple(map(float, n))
        )
        for s, mu, n in zip(qp.cone_starts, qp.mus, qp.normals, strict=True)
    )
    return (qp.P, qp.q, qp.A, qp.b, qp.lb, qp.ub, cones)


class FccqpAdapter(Adapter):
    """fccqp with exact friction cones, warm started across a sequence."""

    exact_cones = True
    warm = True

    def __init__(self, name: str, realtime: bool) -> None:
        import fccqp

        self.name = name
        settings = fccqp.Settings.realtime() if realtime else fccqp.Settings()
        self._solver = fccqp.Solver(settings)

    def prepare(self, qp: WbcQP) -> tuple[Any, ...]:
        return fccqp_arguments(qp)

    def solve(self, data: tuple[Any, ...]) -> SolveOutcome:
        start = time.perf_counter()
        result = self._solver.solve(*data)
        elapsed = time.perf_counter() - start
        status = result.status
        return SolveOutcome(result.x, status.value, status.is_solved(), result.iterations, elapsed)

    def reset(self) -> None:
        self._solver.reset()


class ClarabelAdapter(Adapter):
    """Clarabel with exact second-order cones; construction and solve are timed."""

    name = "clarabel"
    exact_cones = True
    warm = False

    def __init__(self) -> None:
        import clarabel

        self._clarabel = clarabel

    def prepare(self, qp: WbcQP) -> tuple[Any, ...]:
        settings = self._clarabel.DefaultSettings()
        settings.verbose = False
        return (*clarabel_problem(qp), settings)

    def solve(self, data: tuple[Any, ...]) -> SolveOutcome:
        start = time.perf_counter()
        sol = self._clarabel.DefaultSolver(*data).solve()
        elapsed = time.perf_counter() - start
        status = str(sol.status)
        return SolveOutcome(np.array(sol.x), status, status == "Solved", sol.iterations, elapsed)

    def reset(self) -> None:
        """Nothing to forget: every solve is cold."""


class ProxqpAdapter(Adapter):
    """ProxQP dense on an inner pyramid, torque limits as box constraints."""

    exact_cones = False
    warm = True

    def __init__(self, facets: int) -> None:
        import proxsuite

        self.name = f"proxqp-pyr{facets}"
        self._proxqp = proxsuite.proxqp
        self._facets = facets
        self._model: Any = None

    def prepare(self, qp: WbcQP) -> tuple[Any, ...]:
        G, h = _pyramid_rows(qp, self._facets)
        # ProxQP's dense box must cover every variable; +-1e20 is its "no bound".
        lb = np.where(np.isfinite(qp.lb), qp.lb, -1e20)
        ub = np.where(np.isfinite(qp.ub), qp.ub, 1e20)
        return (qp.P, qp.q, qp.A, qp.b, G, np.full(h.shape, -1e20), h, lb, ub)

    def solve(self, data: tuple[Any, ...]) -> SolveOutcome:
        H, A, C = data[0], data[2], data[4]
        dims = (H.shape[0], A.shape[0], C.shape[0])
        dense = self._proxqp.dense
        start = time.perf_counter()
        model = self._model
        if model is not None and (model.model.dim, model.model.n_eq, model.model.n_in) == dims:
            model.settings.initial_guess = self._proxqp.InitialGuess.WARM_START_WITH_PREVIOUS_RESULT
            model.update(*data, update_preconditioner=True)
        else:
            model = dense.QP(*dims, True)
            model.init(*data)
        model.solve()
        elapsed = time.perf_counter() - start
        self._model = model
        info = model.results.info
        solved = info.status == self._proxqp.QPSolverOutput.PROXQP_SOLVED
        name = str(info.status).rsplit(".", 1)[-1]
        return SolveOutcome(np.array(model.results.x), name, solved, int(info.iter), elapsed)

    def reset(self) -> None:
        self._model = None


class OsqpAdapter(Adapter):
    """OSQP on an inner pyramid; setup + solve timed, warm started with the last x, y."""

    exact_cones = False
    warm = True

    def __init__(self, facets: int) -> None:
        import osqp

        self.name = f"osqp-pyr{facets}"
        self._osqp = osqp
        self._facets = facets
        self._previous: tuple[np.ndarray, np.ndarray] | None = None

    def prepare(self, qp: WbcQP) -> tuple[Any, ...]:
        G, h = _pyramid_rows(qp, self._facets)
        idx, (lo, hi) = _torque_box(qp)
        rows = sparse.vstack(
            [sparse.csc_matrix(qp.A), sparse.csc_matrix(G), sparse.eye(qp.n, format="csc")[idx]],
            format="csc",
        )
        lower = np.concatenate([qp.b, np.full(h.shape, -np.inf), lo])
        upper = np.concatenate([qp.b, h, hi])
        return (sparse.csc_matrix(np.triu(qp.P)), np.array(qp.q), rows, lower, upper)

    def solve(self, data: tuple[Any, ...]) -> SolveOutcome:
        prev = self._previous
        warm = prev is not None and prev[0].shape[0] == data[1].shape[0]
        warm = warm and prev[1].shape[0] == data[3].shape[0]
        start = time.perf_counter()
        solver = self._osqp.OSQP()
        solver.setup(*data, verbose=False)
        if warm:
            solver.warm_start(x=prev[0], y=prev[1])
        res = solver.solve(raise_error=False)
        elapsed = time.perf_counter() - start
        status = str(res.info.status)
        x = np.array(res.x, dtype=float) if res.x is not None else np.full(data[1].shape, np.nan)
        self._previous = (x, np.array(res.y)) if np.all(np.isfinite(x)) else None
        return SolveOutcome(x, status, status == "solved", int(res.info.iter), elapsed)

    def reset(self) -> None:
        self._previous = None


class QpsolversAdapter(Adapter):
    """Any qpsolvers backend on the 4-facet inner pyramid, cold, one call per QP."""

    exact_cones = False
    warm = False

    _SPARSE = frozenset({"osqp", "clarabel", "scs", "highs"})

    def __init__(self, solver: str) -> None:
        import qpsolvers

        self.name = f"qpsolvers:{solver}"
        self._qpsolvers = qpsolvers
        self._solver = solver

    def prepare(self, qp: WbcQP) -> Any:
        G, h = _pyramid_rows(qp, 4)
        P, A = np.array(qp.P), np.array(qp.A)
        if self._solver in self._SPARSE:
            P, A, G = sparse.csc_matrix(P), sparse.csc_matrix(A), sparse.csc_matrix(G)
        return self._qpsolvers.Problem(P, np.array(qp.q), G, h, A, np.array(qp.b), qp.lb, qp.ub)

    def solve(self, data: Any) -> SolveOutcome:
        start = time.perf_counter()
        sol = self._qpsolvers.solve_problem(data, solver=self._solver)
        elapsed = time.perf_counter() - start
        found = bool(sol.found)
        x = np.array(sol.x, dtype=float) if sol.x is not None else np.full(data.q.shape, np.nan)
        return SolveOutcome(x, "found" if found else "not found", found, -1, elapsed)

    def reset(self) -> None:
        """Nothing to forget: every solve is cold."""


def _has_module(name: str) -> bool:
    return importlib.util.find_spec(name) is not None


def _qpsolvers_has(solver: str) -> bool:
    if not _has_module("qpsolvers"):
        return False
    import qpsolvers

    import fccqp  # noqa: F401  (registers the "fccqp" backend when it exists)

    return solver in qpsolvers.available_solvers


VARIANTS: dict[str, tuple[Callable[[], Adapter], Callable[[], bool], str]] = {
    "fccqp-realtime": (
        lambda: FccqpAdapter("fccqp-realtime", realtime=True),
        lambda: _has_module("fccqp"),
        "fccqp, Settings.realtime() (15 iterations, eps 1e-4), exact cones, warm",
    ),
    "fccqp-default": (
        lambda: FccqpAdapter("fccqp-default", realtime=False),
        lambda: _has_module("fccqp"),
        "fccqp, Settings() (eps 1e-5), exact cones, warm",
    ),
    "clarabel": (
        ClarabelAdapter,
        lambda: _has_module("clarabel"),
        "Clarabel defaults, exact cones, cold (no warm start)",
    ),
    "proxqp-pyr4": (
        lambda: ProxqpAdapter(4),
        lambda: _has_module("proxsuite"),
        "ProxQP dense defaults, 4-facet inner pyramid, box torques, warm (update)",
    ),
    "osqp-pyr4": (
        lambda: OsqpAdapter(4),
        lambda: _has_module("osqp"),
        "OSQP defaults, 4-facet inner pyramid, warm (warm_start x, y)",
    ),
    "proxqp-pyr8": (
        lambda: ProxqpAdapter(8),
        lambda: _has_module("proxsuite"),
        "ProxQP dense defaults, 8-facet inner pyramid, box torques, warm (update)",
    ),
    "osqp-pyr8": (
        lambda: OsqpAdapter(8),
        lambda: _has_module("osqp"),
        "OSQP defaults, 8-facet inner pyramid, warm (warm_start x, y)",
    ),
    **{
        f"qpsolvers:{s}": (
            (lambda s=s: QpsolversAdapter(s)),
            (lambda s=s: _qpsolvers_has(s)),
            f"qpsolvers.solve_problem(solver={s!r}) defaults, 4-facet inner pyramid, cold",
        )
        for s in ("fccqp", "proxqp", "osqp", "clarabel")
    },
}
"""Variant name -> (adapter factory, availability check, one-line description)."""


def available_variants(names: list[str]) -> tuple[list[str], list[str]]:
    """Split ``names`` into the installed variants and the missing ones."""
    found = [name for name in names if VARIANTS[name][1]()]
    return found, [name for name in names if name not in found]


def make_adapter(name: str) -> Adapter:
    """A fresh adapter of variant ``name``."""
    return VARIANTS[name][0]()


def kkt_factorization_time(qp: WbcQP, repeats: int) -> tuple[float, float]:
    """Median time of one ``dsytrf`` of ``[[P + 1e-6 I, A'], [A, 0]]`` and its accuracy.

    The factorization is what any method that keeps the equalities of this QP exact
    pays at least once, so its time is the speed yardstick of the report. The second
    value is ``||A x - b||_inf`` of the equality-constrained minimizer solved with that
    factorization (``dsytrs``): the "factorization accuracy" an exact-equality solver
    can reach on this QP.
    """
    n, m = qp.n, qp.A.shape[0]
    K = np.zeros((n + m, n + m), order="F")
    K[:n, :n] = qp.P + KKT_REGULARIZATION * np.eye(n)
    K[n:, :n] = qp.A
    K[:n, n:] = qp.A.T
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        lu, ipiv, info = lapack.dsytrf(K, lower=1, lwork=_LWORK_PER_ROW * (n + m))
        times.append(time.perf_counter() - start)
    rhs = np.concatenate([-qp.q, qp.b])
    sol, _ = lapack.dsytrs(lu, ipiv, rhs, lower=1)
    if info != 0:
        return float(np.median(times)), float("nan")
    return float(np.median(times)), qp.equality_residual(sol[:n])
