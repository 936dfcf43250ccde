"""Adapters of the solvers that see the exact friction cones: fccqp, Clarabel, QOCO, SCS.

- fccqp: :class:`fccqp.Solver` with the given settings, warm across a sequence (the
  solver keeps its state; ``reset()`` at sequence boundaries); where the contact points
  change within a sequence, the previous answer carried onto the new QP by its contact
  points (:mod:`benchmarks.contact_map`) is the guess ``x0, y0, z0``, as a controller
  would give it. The map and the carried vectors are made before the timed call (the
  controller's bookkeeping, as DAQP's ``dual_start`` below).
- Clarabel: second-order cones; it has no warm start and no update for new matrices,
  so ``DefaultSolver(...)`` construction and ``solve()`` are both timed.
- QOCO: second-order cones, interior point for real time; its Python interface has
  no warm start, so ``setup`` and ``solve`` are both timed.
- SCS: second-order cones, ADMM on the homogeneous embedding; a new ``SCS`` object per
  QP (its matrices cannot be updated, so setup is timed) warm started with the previous
  ``x, y, s`` of the sequence when the dimensions are unchanged.

The conic data are the ones of :func:`benchmarks.wbc_qp.clarabel_problem`: equalities
as a zero cone, finite bounds as nonnegative rows, each contact force as a 3-dimensional
second-order cone ``(mu n.f, t1.f, t2.f)``.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from benchmarks.adapters import Adapter, Prepared, SolveOutcome, failed_x
from benchmarks.contact_map import ContactMaps, carried
from benchmarks.wbc_qp import WbcQP, clarabel_problem

__all__ = [
    "ClarabelAdapter",
    "FccqpAdapter",
    "QocoAdapter",
    "ScsAdapter",
    "carried_guess",
    "conic_sizes",
    "fccqp_arguments",
]


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


def conic_sizes(qp: WbcQP, rows: int) -> tuple[int, int, int]:
    """Rows of the zero cone, of the nonnegative cone and the number of SOCs.

    ``rows`` is the row count of :func:`~benchmarks.wbc_qp.clarabel_problem`'s ``G``,
    whose blocks come in that order.
    """
    zero, socs = qp.A.shape[0], qp.n_contacts
    return zero, rows - zero - 3 * socs, socs


class FccqpAdapter(Adapter):
    """fccqp with exact friction cones, warm started across a sequence and across its
    contact changes (:func:`carried_guess`)."""

    def __init__(self, name: str, settings: Any) -> None:
        import fccqp

        self.name = name
        self._solver = fccqp.Solver(settings)
        self._maps = ContactMaps()
        self._previous: tuple[WbcQP, Any] | None = None   # the last QP and its Result

    def prepare(self, qp: WbcQP) -> Prepared:
        return Prepared(fccqp_arguments(qp), qp)

    def solve(self, data: Prepared) -> SolveOutcome:
        guess = carried_guess(self._maps, self._previous, data.qp)
        start = time.perf_counter()
        result = self._solver.solve(*data.arguments, **guess)
        elapsed = time.perf_counter() - start
        self._previous = (data.qp, result)
        status = result.status
        return SolveOutcome(result.x, status.value, status.is_solved(), result.iterations, elapsed)

    def reset(self) -> None:
        self._solver.reset()
        self._previous = None


def carried_guess(maps: ContactMaps, previous: tuple[WbcQP, Any] | None,
                  qp: WbcQP) -> dict[str, np.ndarray]:
    """The guess ``{x0, y0, z0}`` of ``fccqp.Solver.solve`` for ``qp``: the previous
    QP's answer (``previous``, the QP and its ``fccqp.Result``) carried onto ``qp`` by
    its contact points when they changed, new points' entries zero; empty (the solver's
    own warm start) when they did not, at a sequence start, or when the previous answer
    is an infeasibility certificate's point or not finite (the solver keeps none)."""
    if previous is None:
        return {}
    before, result = previous
    cmap = maps.changed(before, qp)
    if (cmap is None or result.status.is_infeasible()
            or not all(np.all(np.isfinite(v)) for v in (result.x, result.y, result.z))):
        return {}
    return {"x0": carried(result.x, cmap.variables), "y0": carried(result.y, cmap.rows),
            "z0": carried(result.z, cmap.variables)}


class ClarabelAdapter(Adapter):
    """Clarabel with exact second-order cones; construction and solve are timed.

    ``tol`` sets ``tol_gap_abs``, ``tol_gap_rel`` and ``tol_feas`` (Clarabel's
    defaults, 1e-8, when ``None``).
    """

    def __init__(self, name: str, tol: float | None = None) -> None:
        import clarabel

        self.name = name
        self._clarabel = clarabel
        self._tol = tol

    def prepare(self, qp: WbcQP) -> tuple[Any, ...]:
        settings = self._clarabel.DefaultSettings()
        settings.verbose = False
        if self._tol is not None:
            settings.tol_gap_abs = settings.tol_gap_rel = settings.tol_feas = self._tol
        return (*clarabel_problem(qp), settings)

    def solve(self, data: tuple[Any, ...]) -> SolveOutcome:
        start = time.perf_counter()
        sol = self._clarabel.DefaultSolver(*data).solve()
        elapsed = time.perf_counter() - start
        status = str(sol.status)
        return SolveOutcome(np.array(sol.x), status, status == "Solved", sol.iterations, elapsed)


class QocoAdapter(Adapter):
    """QOCO with exact second-order cones; ``setup`` and ``solve`` are timed.

    ``tol`` sets ``abstol`` and ``reltol`` (QOCO's defaults, 1e-7, when ``None``).
    """

    def __init__(self, name: str, tol: float | None = None) -> None:
        import qoco

        self.name = name
        self._qoco = qoco
        self._settings = {"verbose": False}
        if tol is not None:
            self._settings |= {"abstol": tol, "reltol": tol}

    def prepare(self, qp: WbcQP) -> tuple[Any, ...]:
        P, q, G, h, _ = clarabel_problem(qp)
        zero, nonneg, socs = conic_sizes(qp, G.shape[0])
        A, b = G[:zero], h[:zero]
        cones = np.full(socs, 3, dtype=np.int32)
        return (qp.n, G.shape[0] - zero, zero, P, q, A, b, G[zero:].tocsc(), h[zero:],
                nonneg, socs, cones)

    def solve(self, data: tuple[Any, ...]) -> SolveOutcome:
        start = time.perf_counter()
        solver = self._qoco.QOCO()
        solver.setup(*data, **self._settings)
        res = solver.solve()
        elapsed = time.perf_counter() - start
        status = str(res.status)
        x = np.array(res.x, dtype=float)
        return SolveOutcome(x, status, status == "QOCO_SOLVED", int(res.iters), elapsed)


class ScsAdapter(Adapter):
    """SCS with exact second-order cones, warm started with the previous ``x, y, s``.

    ``tol`` sets ``eps_abs`` and ``eps_rel`` (SCS's defaults, 1e-4, when ``None``).
    """

    def __init__(self, name: str, tol: float | None = None) -> None:
        import scs

        self.name = name
        self._scs = scs
        self._settings: dict[str, Any] = {"verbose": False}
        if tol is not None:
            self._settings |= {"eps_abs": tol, "eps_rel": tol}
        self._previous: dict[str, np.ndarray] | None = None

    def prepare(self, qp: WbcQP) -> tuple[dict[str, Any], dict[str, Any]]:
        P, q, G, h, _ = clarabel_problem(qp)
        zero, nonneg, socs = conic_sizes(qp, G.shape[0])
        return {"P": P, "A": G, "b": h, "c": q}, {"z": zero, "l": nonneg, "q": [3] * socs}

    def solve(self, data: tuple[dict[str, Any], dict[str, Any]]) -> SolveOutcome:
        problem, cone = data
        prev = self._previous
        warm = (
            prev is not None
            and prev["x"].shape == problem["c"].shape
            and prev["y"].shape == problem["b"].shape
        )
        start = time.perf_counter()
        solver = self._scs.SCS(problem, cone, **self._settings)
        sol = solver.solve(warm_start=warm, **(prev if warm else {}))
        elapsed = time.perf_counter() - start
        status = str(sol["info"]["status"])
        x = np.array(sol["x"], dtype=float)
        if not np.all(np.isfinite(x)):
            x = failed_x(problem["c"].shape[0])
        self._previous = (
            {k: np.array(sol[k]) for k in ("x", "y", "s")} if np.all(np.isfinite(x)) else None
        )
        return SolveOutcome(x, status, status == "solved", int(sol["info"]["iter"]), elapsed)

    def reset(self) -> None:
        self._previous = None
