"""The interface every benchmarked solver variant implements, and its shared helpers.

Every adapter splits a solve in two: :meth:`Adapter.prepare` turns a
:class:`~benchmarks.wbc_qp.WbcQP` into the solver's own input (matrix conversion,
pyramid rows, cone lists) outside the timed region; :meth:`Adapter.solve` times the
solver's own Python call with :func:`time.perf_counter`. Adapters that warm start keep
their state between calls; :meth:`Adapter.reset` forgets it at a sequence boundary.
The adapters themselves live in :mod:`benchmarks.exact_solvers` (solvers that see the
exact friction cones) and :mod:`benchmarks.pyramid_solvers` (solvers that see a
linearized pyramid).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np

from benchmarks.wbc_qp import WbcQP

__all__ = ["Adapter", "Prepared", "SolveOutcome", "failed_x", "torque_box"]


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


class Prepared(NamedTuple):
    """The prepared input of an adapter that carries its previous answer across a
    contact change (:mod:`benchmarks.contact_map`)."""

    arguments: tuple[Any, ...]
    """The solver's own positional arguments."""
    qp: WbcQP
    """The QP they came from, whose contact points the map matches."""


class Adapter(ABC):
    """Common interface of the benchmarked variants.

    Attributes
    ----------
    name
        Variant name, a key of :data:`benchmarks.solvers.VARIANTS`.
    """

    name: str

    @abstractmethod
    def prepare(self, qp: WbcQP) -> Any:
        """Convert ``qp`` to the solver's input; not timed."""

    @abstractmethod
    def solve(self, data: Any) -> SolveOutcome:
        """Solve prepared data, timing only the solver's own call."""

    def reset(self) -> None:  # noqa: B027  (a default on purpose, not abstract)
        """Forget warm-start state (called at each sequence boundary).

        Solvers that solve every QP cold have nothing to forget and keep this default.
        """


def torque_box(qp: WbcQP) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Indices, lower and upper bounds of the finite bounds of ``qp`` (the torques)."""
    idx = np.flatnonzero(np.isfinite(qp.lb) | np.isfinite(qp.ub))
    return idx, qp.lb[idx], qp.ub[idx]


def failed_x(n: int) -> np.ndarray:
    """The ``x`` recorded when a solver returns no point: NaNs, judged as a failure."""
    return np.full(n, np.nan)
