"""The previous tick's answer carried onto a QP whose contacts changed.

The QP's layout (:mod:`benchmarks.wbc_qp`) groups the soft-contact slacks ``eps`` and
the forces ``lambda_c`` by contact point and stacks three soft-contact rows per point
(and, for the pyramid solvers, ``facets + 1`` pyramid rows per point), so when a contact
is made or broken the entries of the points that stay move within ``x`` and the rows.
The solver cannot tell them from the matrices; the controller knows which points it
kept, and so does the benchmark (:attr:`benchmarks.wbc_qp.WbcQP.contacts`). A
:class:`ContactMap` gives, for each entry of the new QP's vectors, the entry of the
previous QP's it continues (-1 for a new point's entries, which start at zero), and
:func:`carried` moves a vector with it: the warm start a controller would hand its
solver at a contact change (``fccqp.Solver.solve``'s ``x0, y0, z0``, DAQP's
``dual_start``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from benchmarks.testsets import LAYOUT_NAMES
from benchmarks.wbc_qp import WbcQP

__all__ = ["ContactMap", "ContactMaps", "carried", "contact_map", "shifted"]

_PER_POINT = ("eps", "lambda_c")
"""The blocks of ``x`` with three entries per contact point; the others keep their size."""


@dataclass(frozen=True)
class ContactMap:
    """Where each entry of a QP was in the previous QP of the sequence.

    Attributes
    ----------
    variables
        Per entry of ``x``, its index in the previous ``x`` (-1: a new point's).
    rows
        Per row of ``A``, the previous row it continues (-1: a new point's).
    points
        Per contact point, its index among the previous QP's points (-1: new).
    """

    variables: np.ndarray
    rows: np.ndarray
    points: np.ndarray

    def groups(self, width: int) -> np.ndarray:
        """The map of rows stacked ``width`` per contact point (a pyramid's rows)."""
        return _grouped(self.points, width)


def contact_map(previous: WbcQP, qp: WbcQP) -> ContactMap:
    """The map from ``previous`` to ``qp``, two QPs of one robot in a sequence, whose
    contact points are matched by name.

    Raises
    ------
    ValueError
        When a QP's contact points are not named, or a block other than the contacts'
        changed size (not the same robot and tasks).
    """
    for name, one in (("previous", previous), ("qp", qp)):
        if len(one.contacts) != one.n_contacts:
            raise ValueError(f"{name} has {one.n_contacts} contacts but "
                             f"{len(one.contacts)} named")
    where = {point: k for k, point in enumerate(previous.contacts)}
    points = np.array([where.get(point, -1) for point in qp.contacts], dtype=np.intp)
    triples = _grouped(points, 3)
    variables = []
    for block in LAYOUT_NAMES:
        before, after = previous.layout[block], qp.layout[block]
        if block in _PER_POINT:
            variables.append(shifted(triples, before.start))
        elif before.stop - before.start != after.stop - after.start:
            raise ValueError(f"block {block} has {before.stop - before.start} entries in "
                             f"previous and {after.stop - after.start} in qp")
        else:
            variables.append(np.arange(before.start, before.stop))
    common = previous.A.shape[0] - 3 * previous.n_contacts   # dynamics and holonomic rows
    rows = np.concatenate([np.arange(common), shifted(triples, common)])
    return ContactMap(np.concatenate(variables), rows, points)


class ContactMaps:
    """The maps between the contact sets a controller has met, made once per pair: a
    controller would hold them for its gait's few contact sets, so that a contact change
    costs it only the moves of :func:`carried`."""

    def __init__(self) -> None:
        self._maps: dict[tuple[object, ...], ContactMap] = {}

    def changed(self, previous: WbcQP, qp: WbcQP) -> ContactMap | None:
        """The map from ``previous`` to ``qp`` when their contact points differ (a
        contact made or broken, a trot's switch), else None."""
        if previous.contacts == qp.contacts:
            return None
        key = (previous.contacts, qp.contacts, previous.n, qp.n)
        if key not in self._maps:
            self._maps[key] = contact_map(previous, qp)
        return self._maps[key]


def carried(values: np.ndarray, positions: np.ndarray) -> np.ndarray:
    """``values`` (a vector of the previous QP) on the new QP: ``values[positions]``,
    zero where ``positions`` is -1."""
    out = np.zeros(positions.shape[0])
    kept = positions >= 0
    out[kept] = np.asarray(values)[positions[kept]]
    return out


def shifted(positions: np.ndarray, offset: int) -> np.ndarray:
    """``positions`` plus ``offset`` where they are not -1 (a block stacked after
    ``offset`` entries of the previous vector)."""
    return np.where(positions >= 0, positions + offset, -1)


def _grouped(points: np.ndarray, width: int) -> np.ndarray:
    """The entries of ``width`` per point, for the points' previous indices."""
    entries = points[:, None] * width + np.arange(width)
    return np.where(points[:, None] >= 0, entries, -1).reshape(-1)
