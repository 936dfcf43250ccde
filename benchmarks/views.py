"""The report's views: which QPs each one times, in which order, and from what start.

A controller meets more than the median tick of a smooth 2 ms sequence. Each timed view
is a :class:`Path` through a test set, with the QPs before which the solver is reset:

``warm``
    every QP in controller-loop order, warm from the previous QP, reset at each sequence
    start: what a controller running every tick meets.
``cold``
    every QP from a reset solver: a controller's first tick, or its tick after a fault.
    fccqp: ``Solver.reset()`` (the workspace of the structure is kept; the warm-up
    solved the first QP of each structure untimed); DAQP without ``dual_start``; ProxQP
    a new model; OSQP and SCS without a warm start; Clarabel, QOCO, PIQP and quadprog
    are cold in every view.
``every 5th``, ``every 10th``
    every 5th (10th) QP of each sequence, from its first, warm from the previous kept
    QP: a controller at a lower rate, or one that skips ticks, whose consecutive QPs
    lie further apart.
``contact change``
    the warm path's QPs whose stance (the feet in contact) differs from the previous
    QP's: no passes of their own, a selection of the warm rows.

The peers' settings sweeps and the qpsolvers calls run the warm path only
(:func:`runs_every_view`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from benchmarks.solvers import VARIANTS
from benchmarks.testsets import TestSet

__all__ = [
    "COARSE_STEPS",
    "CONTACT_CHANGE",
    "VIEWS",
    "Path",
    "coarse_path",
    "cold_path",
    "contact_changes",
    "runs_every_view",
    "ticks",
    "timed_paths",
    "view_rows",
    "warm_path",
]

COARSE_STEPS = (5, 10)
"""The coarse views keep every 5th and every 10th QP of each sequence."""

CONTACT_CHANGE = "contact change"
"""Name of the view of the warm path's contact-change ticks."""

VIEWS = ("warm", "cold", *(f"every {k}th" for k in COARSE_STEPS), CONTACT_CHANGE)
"""Every view, in report order."""


@dataclass(frozen=True, eq=False)
class Path:
    """QPs of ``test_set`` solved in the order of ``indices``, the solver reset before
    each position where ``fresh`` is true (one pass of a variant walks the path once).
    """

    view: str
    test_set: TestSet
    indices: np.ndarray
    fresh: np.ndarray

    def __len__(self) -> int:
        return int(self.indices.size)


def ticks(test_set: TestSet) -> np.ndarray:
    """Each QP's position in its sequence (0 at a sequence's first QP)."""
    seq = np.asarray(test_set.sequence)
    starts = np.r_[True, seq[1:] != seq[:-1]]
    first = np.maximum.accumulate(np.where(starts, np.arange(seq.size), 0))
    return np.arange(seq.size) - first


def _sequence_starts(test_set: TestSet, indices: np.ndarray) -> np.ndarray:
    seq = np.asarray(test_set.sequence)[indices]
    return np.r_[True, seq[1:] != seq[:-1]] if seq.size else np.zeros(0, dtype=bool)


def warm_path(test_set: TestSet) -> Path:
    """Every QP, warm from the previous one, reset at each sequence start."""
    idx = np.arange(len(test_set))
    return Path("warm", test_set, idx, _sequence_starts(test_set, idx))


def cold_path(test_set: TestSet) -> Path:
    """Every QP from a reset solver."""
    idx = np.arange(len(test_set))
    return Path("cold", test_set, idx, np.ones(idx.size, dtype=bool))


def coarse_path(test_set: TestSet, step: int) -> Path:
    """Every ``step``-th QP of each sequence from its first, warm from the previous kept
    QP, reset at each sequence start."""
    idx = np.flatnonzero(ticks(test_set) % step == 0)
    return Path(f"every {step}th", test_set, idx, _sequence_starts(test_set, idx))


def contact_changes(path: Path) -> np.ndarray:
    """Per position of ``path``: the stance differs from the previous position's and the
    solver was not reset in between (a contact made or broken mid-sequence).

    Raises
    ------
    ValueError
        If the test set records no stance (a file written before generator version 2).
    """
    stance = path.test_set.stance
    if len(stance) != len(path.test_set):
        raise ValueError(
            f"the {path.test_set.robot} test set records no stance per QP; generate it again"
        )
    kept = [stance[i] for i in path.indices]
    changed = [i > 0 and kept[i] != kept[i - 1] for i in range(len(kept))]
    return np.array(changed, dtype=bool) & ~path.fresh


def timed_paths(main: TestSet, coarse: TestSet) -> list[Path]:
    """The paths of a run: warm and cold through ``main``, the coarse views through
    ``coarse`` (the full preset's sequences, or ``main`` itself)."""
    return [warm_path(main), cold_path(main), *(coarse_path(coarse, k) for k in COARSE_STEPS)]


def runs_every_view(variant: str) -> bool:
    """Whether ``variant`` runs every path (a solver at its defaults through its own API)
    or the warm path alone (settings sweeps, qpsolvers calls)."""
    v = VARIANTS[variant]
    return v.direct and not v.sweep


def view_rows(rows: Sequence[dict[str, object]], view: str) -> list[dict[str, object]]:
    """The result rows of ``view``: those of its path, or the warm path's contact-change
    ticks for :data:`CONTACT_CHANGE`."""
    if view == CONTACT_CHANGE:
        return [r for r in rows if r["view"] == "warm" and r["contact_change"]]
    return [r for r in rows if r["view"] == view]
