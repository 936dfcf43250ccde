"""Point labels that do not pile up: the work-precision figure's settings.

Points of one solver that sit within a few pixels of each other (fccqp's presets and
tolerances often land on one spot) share one label listing their settings; each label
then takes the first of a ring of positions around its point where it overlaps no label
placed before it and no marker and stays within the axes' width and below their top, or
the position that breaks fewest of these.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import matplotlib.pyplot as plt
from matplotlib.transforms import Bbox

__all__ = ["Point", "place_labels"]

_MERGE_PX = 8.0
"""Points of one solver closer than this (pixels) share a label."""
_OFFSETS = [(dx, dy) for r in (6, 14, 24, 36) for dx, dy in
            ((r, 2), (r, -r), (-r, 2), (-r, -r), (0, r), (0, -r - 6), (r, r), (-r, r))]
"""Candidate offsets (points) of a label's anchor from its point, nearest first."""
_MARKER_PX = 5.0
"""Half the size (pixels) of the box a marker keeps free."""


@dataclass(frozen=True)
class Point:
    """A labelled point in data coordinates (``transform`` says which)."""

    x: float
    y: float
    family: str
    text: str
    colour: str


def _groups(points: Sequence[Point], transform) -> list[list[Point]]:
    """Points of one family within :data:`_MERGE_PX` of the group's first point."""
    groups: list[list[Point]] = []
    where: list[tuple[float, float]] = []
    for p in points:
        px = transform.transform((p.x, p.y))
        for group, (gx, gy) in zip(groups, where, strict=True):
            if group[0].family == p.family and abs(gx - px[0]) + abs(gy - px[1]) < _MERGE_PX:
                group.append(p)
                break
        else:
            groups.append([p])
            where.append((float(px[0]), float(px[1])))
    return groups


def place_labels(ax: plt.Axes, points: Sequence[Point], transform=None,
                 fontsize: float = 6.5) -> None:
    """Label ``points`` on ``ax`` (data coordinates unless ``transform`` is given),
    merging near points of one family and avoiding overlaps."""
    fig = ax.figure
    transform = transform or ax.transData
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    to_px = fig.dpi / 72.0
    markers = []
    for p in points:
        x, y = transform.transform((p.x, p.y))
        markers.append(Bbox.from_extents(x - _MARKER_PX, y - _MARKER_PX, x + _MARKER_PX,
                                         y + _MARKER_PX))
    frame = ax.get_window_extent(renderer)
    taken: list[Bbox] = []
    for group in _groups(points, transform):
        text = ", ".join(dict.fromkeys(p.text for p in group))
        anchor = group[0]
        label = ax.annotate(text, (anchor.x, anchor.y), xycoords=transform, xytext=(0, 0),
                            textcoords="offset points", fontsize=fontsize,
                            color=anchor.colour, va="bottom")
        best, best_cost = None, None
        for dx, dy in _OFFSETS:
            label.xyann = (dx, dy)
            label.set_horizontalalignment("left" if dx >= 0 else "right")
            box = label.get_window_extent(renderer).padded(1.0 * to_px)
            outside = not (frame.x0 <= box.x0 and box.x1 <= frame.x1 and box.y1 <= frame.y1)
            cost = (sum(box.overlaps(b) for b in taken) + sum(box.overlaps(b) for b in markers)
                    + 2 * outside)
            if best_cost is None or cost < best_cost:
                best, best_cost = ((dx, dy), box), cost
            if cost == 0:
                break
        label.xyann = best[0]
        label.set_horizontalalignment("left" if best[0][0] >= 0 else "right")
        taken.append(best[1])
