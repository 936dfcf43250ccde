"""Adapters of the solvers that see an inner friction pyramid instead of the exact cones.

The pyramid rows ``G x <= h`` come from :meth:`benchmarks.wbc_qp.WbcQP.pyramid` with
``inner=True`` (so every pyramid answer is cone-feasible, but restricted).

- ProxQP (dense): the first QP of a sequence builds and ``init``-s a model; later ones
  ``update`` it and warm start from the previous result when the dimensions match.
- OSQP: ``setup`` and ``solve`` timed for every QP (the sparsity pattern changes),
  warm started with ``warm_start(x, y)`` from the previous solution of the sequence.
- DAQP (dense dual active set): one ``daqp.solve`` call, equalities as ``sense = 5``
  rows and bounds as its simple bounds, warm started with the previous multipliers
  (``dual_start``, which sets the initial working set); where the contact points change
  within a sequence, the multipliers carried onto the new rows by the contact points
  (:mod:`benchmarks.contact_map`; a new point's pyramid rows at zero), as fccqp's
  adapter carries its answer. The carried start is made before the timed call.
- quadprog (Goldfarb-Idnani dual active set): one ``solve_qp`` call, cold (it has no
  warm start and no tolerance setting).
- PIQP (dense backend, proximal interior point): ``setup`` and ``solve`` timed, cold
  (PIQP has no warm start).
- ``qpsolvers:<name>``: the 4-facet pyramid through ``qpsolvers.solve_problem``, cold,
  as a one-call qpsolvers user sees it; qpsolvers has no cones, so ``qpsolvers:fccqp``
  also gets the pyramid rows.
"""

from __future__ import annotations

import time
import warnings
from typing import Any

import numpy as np
from scipy import sparse

from benchmarks.adapters import Adapter, Prepared, SolveOutcome, failed_x, torque_box
from benchmarks.contact_map import ContactMaps, carried, shifted
from benchmarks.wbc_qp import WbcQP

__all__ = [
    "DaqpAdapter",
    "OsqpAdapter",
    "PiqpAdapter",
    "ProxqpAdapter",
    "QpsolversAdapter",
    "QuadprogAdapter",
]

_NO_BOUND = 1e20
"""What ProxQP's dense box takes as "no bound"."""


def _pyramid(qp: WbcQP, facets: int) -> tuple[np.ndarray, np.ndarray]:
    return qp.pyramid(facets=facets, inner=True)


class ProxqpAdapter(Adapter):
    """ProxQP dense on an inner pyramid, torque limits as box constraints.

    ``eps`` sets ``eps_abs`` (ProxQP's default, 1e-5, when ``None``).
    """

    def __init__(self, name: str, facets: int, eps: float | None = None) -> None:
        import proxsuite

        self.name = name
        self._proxqp = proxsuite.proxqp
        self._facets = facets
        self._eps = eps
        self._model: Any = None

    def prepare(self, qp: WbcQP) -> tuple[Any, ...]:
        G, h = _pyramid(qp, self._facets)
        lb = np.where(np.isfinite(qp.lb), qp.lb, -_NO_BOUND)
        ub = np.where(np.isfinite(qp.ub), qp.ub, _NO_BOUND)
        return (qp.P, qp.q, qp.A, qp.b, G, np.full(h.shape, -_NO_BOUND), h, lb, ub)

    def solve(self, data: tuple[Any, ...]) -> SolveOutcome:
        H, A, C = data[0], data[2], data[4]
        dims = (H.shape[0], A.shape[0], C.shape[0])
        start = time.perf_counter()
        model = self._model
        if model is not None and (model.model.dim, model.model.n_eq, model.model.n_in) == dims:
            model.settings.initial_guess = self._proxqp.InitialGuess.WARM_START_WITH_PREVIOUS_RESULT
            model.update(*data, update_preconditioner=True)
        else:
            model = self._proxqp.dense.QP(*dims, True)
            if self._eps is not None:
                model.settings.eps_abs = self._eps
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
    """OSQP on an inner pyramid; setup + solve timed, warm started with the last x, y.

    ``eps`` sets ``eps_abs`` and ``eps_rel`` (OSQP's defaults, 1e-3, when ``None``).
    """

    def __init__(self, name: str, facets: int, eps: float | None = None) -> None:
        import osqp

        self.name = name
        self._osqp = osqp
        self._facets = facets
        self._settings: dict[str, Any] = {"verbose": False}
        if eps is not None:
            self._settings |= {"eps_abs": eps, "eps_rel": eps}
        self._previous: tuple[np.ndarray, np.ndarray] | None = None

    def prepare(self, qp: WbcQP) -> tuple[Any, ...]:
        G, h = _pyramid(qp, self._facets)
        idx, lo, hi = torque_box(qp)
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
        solver.setup(*data, **self._settings)
        if warm:
            solver.warm_start(x=prev[0], y=prev[1])
        res = solver.solve(raise_error=False)
        elapsed = time.perf_counter() - start
        status = str(res.info.status)
        x = np.array(res.x, dtype=float) if res.x is not None else failed_x(data[1].shape[0])
        self._previous = (x, np.array(res.y)) if np.all(np.isfinite(x)) else None
        return SolveOutcome(x, status, status == "solved", int(res.info.iter), elapsed)

    def reset(self) -> None:
        self._previous = None


class DaqpAdapter(Adapter):
    """DAQP on the 4-facet inner pyramid, warm started with the previous multipliers,
    carried across a contact change (:meth:`_dual_start`).

    ``tol`` sets ``primal_tol`` (DAQP's default, 1e-6, when ``None``); ``carry=False``
    keeps the multipliers only where the sizes match, as a caller without the contact
    map (the comparison's "before").
    """

    _EQUALITY = 5
    """DAQP's ``sense`` flag of an equality row."""
    _FACETS = 4
    """Facets of the pyramid (rows per contact point: one more, the normal force's)."""

    def __init__(self, name: str, tol: float | None = None, carry: bool = True) -> None:
        import daqp

        self.name = name
        self._daqp = daqp
        self._settings = {} if tol is None else {"primal_tol": tol}
        self._carry = carry
        self._maps = ContactMaps()
        self._previous: tuple[WbcQP, np.ndarray] | None = None   # the last QP and its lam

    def prepare(self, qp: WbcQP) -> Prepared:
        G, h = _pyramid(qp, self._FACETS)
        m = qp.A.shape[0]
        rows = np.ascontiguousarray(np.vstack([qp.A, G]))
        upper = np.concatenate([qp.ub, qp.b, h])
        lower = np.concatenate([qp.lb, qp.b, np.full(h.shape, -np.inf)])
        sense = np.zeros(upper.shape, dtype=np.int32)
        sense[qp.n : qp.n + m] = self._EQUALITY
        return Prepared((np.array(qp.P), np.array(qp.q), rows, upper, lower, sense), qp)

    def solve(self, data: Prepared) -> SolveOutcome:
        lam = self._dual_start(data.qp)
        warm = {} if lam is None else {"dual_start": lam}
        start = time.perf_counter()
        x, _, exitflag, info = self._daqp.solve(*data.arguments, **self._settings, **warm)
        elapsed = time.perf_counter() - start
        solved = exitflag == 1
        x = np.array(x, dtype=float)
        self._previous = (data.qp, np.array(info["lam"])) if solved else None
        return SolveOutcome(x, f"exitflag {exitflag}", solved, int(info["iterations"]), elapsed)

    def _dual_start(self, qp: WbcQP) -> np.ndarray | None:
        """The previous multipliers for ``qp``'s bounds and rows ``[x, A, pyramid]``: as
        they were when the contact points did not change, else carried by the points
        (:class:`benchmarks.contact_map.ContactMap`); None at a sequence start or after
        a failed solve."""
        if self._previous is None:
            return None
        before, lam = self._previous
        cmap = self._maps.changed(before, qp) if self._carry else None
        if cmap is None:   # the same points, points without names, or no carry: as they were
            rows = qp.n + qp.A.shape[0] + (self._FACETS + 1) * qp.n_contacts
            return lam if lam.shape[0] == rows else None
        n, m = before.n, before.A.shape[0]
        positions = np.concatenate([cmap.variables, shifted(cmap.rows, n),
                                    shifted(cmap.groups(self._FACETS + 1), n + m)])
        return carried(lam, positions)

    def reset(self) -> None:
        self._previous = None


class QuadprogAdapter(Adapter):
    """quadprog (Goldfarb-Idnani) on the 4-facet inner pyramid, cold, no settings."""

    def __init__(self, name: str) -> None:
        import quadprog

        self.name = name
        self._quadprog = quadprog

    def prepare(self, qp: WbcQP) -> tuple[Any, ...]:
        G, h = _pyramid(qp, 4)
        idx, lo, hi = torque_box(qp)
        eye = np.eye(qp.n)[idx]
        # quadprog: minimize 1/2 x'Gx - a'x subject to C'x >= b, the first meq rows equal.
        C = np.vstack([qp.A, -G, eye, -eye]).T
        b = np.concatenate([qp.b, -h, lo, -hi])
        return (np.array(qp.P), -np.array(qp.q), np.array(C), b, qp.A.shape[0])

    def solve(self, data: tuple[Any, ...]) -> SolveOutcome:
        start = time.perf_counter()
        try:
            out = self._quadprog.solve_qp(*data)
        except ValueError as exc:  # quadprog's way of saying "infeasible" or "not definite"
            elapsed = time.perf_counter() - start
            return SolveOutcome(failed_x(data[1].shape[0]), str(exc), False, -1, elapsed)
        elapsed = time.perf_counter() - start
        return SolveOutcome(np.array(out[0]), "solved", True, int(out[3][0]), elapsed)


class PiqpAdapter(Adapter):
    """PIQP's dense backend on the 4-facet inner pyramid; setup + solve timed, cold.

    ``tol`` sets ``eps_abs`` and ``eps_rel = tol / 10``, the ratio of PIQP's defaults
    (1e-8 and 1e-9, kept when ``None``).
    """

    def __init__(self, name: str, tol: float | None = None) -> None:
        import piqp

        self.name = name
        self._piqp = piqp
        self._tol = tol

    def prepare(self, qp: WbcQP) -> tuple[Any, ...]:
        G, h = _pyramid(qp, 4)
        return (np.asfortranarray(qp.P), np.array(qp.q), np.asfortranarray(qp.A),
                np.array(qp.b), np.asfortranarray(G), np.full(h.shape, -np.inf), h,
                np.array(qp.lb), np.array(qp.ub))

    def solve(self, data: tuple[Any, ...]) -> SolveOutcome:
        start = time.perf_counter()
        solver = self._piqp.DenseSolver()
        solver.settings.verbose = False
        if self._tol is not None:
            solver.settings.eps_abs = self._tol
            solver.settings.eps_rel = self._tol / 10
        solver.setup(*data)
        status = solver.solve()
        elapsed = time.perf_counter() - start
        x = np.array(solver.result.x, dtype=float)
        name = str(status).rsplit(".", 1)[-1]
        solved = status == self._piqp.PIQP_SOLVED
        return SolveOutcome(x, name, solved, int(solver.result.info.iter), elapsed)


class QpsolversAdapter(Adapter):
    """Any qpsolvers backend on the 4-facet inner pyramid, cold, one call per QP.

    qpsolvers calls OSQP's ``solve()`` without ``raise_error``, on which OSQP 1.x warns
    that the default will change; the failure is read from the status either way, so
    that warning is silenced (once, not in the timed call).
    """

    _SPARSE = frozenset({"osqp", "clarabel", "scs", "highs"})

    def __init__(self, name: str, solver: str) -> None:
        import qpsolvers

        warnings.filterwarnings("ignore", message="The default value of raise_error",
                                category=PendingDeprecationWarning)
        self.name = name
        self._qpsolvers = qpsolvers
        self._solver = solver

    def prepare(self, qp: WbcQP) -> Any:
        G, h = _pyramid(qp, 4)
        P, A = np.array(qp.P), np.array(qp.A)
        if self._solver in self._SPARSE:
            P, A, G = sparse.csc_matrix(P), sparse.csc_matrix(A), sparse.csc_matrix(G)
        return self._qpsolvers.Problem(P, np.array(qp.q), G, h, A, np.array(qp.b), qp.lb, qp.ub)

    def solve(self, data: Any) -> SolveOutcome:
        start = time.perf_counter()
        sol = self._qpsolvers.solve_problem(data, solver=self._solver)
        elapsed = time.perf_counter() - start
        found = bool(sol.found)
        x = np.array(sol.x, dtype=float) if sol.x is not None else failed_x(data.q.shape[0])
        return SolveOutcome(x, "found" if found else "not found", found, -1, elapsed)
