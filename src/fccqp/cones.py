"""Cone blocks of the decision vector: the user-facing specs and their flat form.

A cone constrains a contiguous block ``x[start:start + dim]``:

- :class:`FrictionCone` -- ``{f in R^3 : ||f - (n'f) n|| <= mu * n'f}``, the Coulomb
  friction cone about the unit normal ``n`` (default ``(0, 0, 1)``, so the block is
  ``(fx, fy, fz)`` with the normal force last, as in the paper).
- :class:`SecondOrderCone` -- ``{(t, v) : ||v|| <= t}`` of any dimension ``>= 2``.

The compiled kernels never see these objects: :func:`flatten_cones` turns them into
:class:`ConeArrays`, plain arrays of kinds, offsets, sizes, friction coefficients and
normals. :data:`KINDS` is the registry of the kinds on the Python side: each spec class
with its kind code (the compiled core's, ``fccqp/cone_dispatch.pxd``) and the function
that validates a spec into its block size and parameters. Adding a kind: its spec class
and flattening function here, its entry in :data:`KINDS` and in :data:`Cone`; the
compiled side is its module ``fccqp/cone_<kind>.pxd`` and its branches in
``fccqp/cone_dispatch.pxd``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from fccqp.fast_checks import cone_key, upright_friction_arrays

FRICTION = 0
"""Kind code of a friction cone in :class:`ConeArrays` (``fccqp/cone_friction.pxd``)."""
SECOND_ORDER = 1
"""Kind code of a standard second-order cone in :class:`ConeArrays` (``fccqp/cone_soc.pxd``)."""

_UNIT_TOLERANCE = 1e-8


@dataclass(frozen=True)
class FrictionCone:
    """Friction cone on ``x[start:start + 3]``.

    Parameters
    ----------
    start : int
        Index of the first of the three force entries.
    mu : float
        Friction coefficient, finite and positive.
    normal : sequence of 3 floats, optional
        Unit contact normal; ``None`` means ``(0, 0, 1)``: the block is
        ``(fx, fy, fz)`` with the normal force last.
    """

    start: int
    mu: float
    normal: tuple[float, float, float] | None = None

    @property
    def dim(self) -> int:
        """Number of entries of ``x`` in the block (always 3)."""
        return 3


@dataclass(frozen=True)
class SecondOrderCone:
    """Second-order (Lorentz) cone ``||x[start+1:start+dim]|| <= x[start]``.

    Parameters
    ----------
    start : int
        Index of the first entry (the cone's "t").
    dim : int
        Size of the block, at least 2.
    """

    start: int
    dim: int


Cone = FrictionCone | SecondOrderCone


@dataclass(frozen=True)
class ConeArrays:
    """Flat description of cone blocks for the compiled kernels.

    All arrays have one entry per cone, ``normal`` one row per cone (unused rows of
    second-order cones hold zeros). ``offset`` indexes the vector the cone acts on,
    which the solver sets to the position of the block in its constrained-entry
    vector, not in ``x``.
    """

    kind: np.ndarray
    offset: np.ndarray
    dim: np.ndarray
    mu: np.ndarray
    normal: np.ndarray

    @property
    def count(self) -> int:
        """Number of cones."""
        return int(self.kind.shape[0])

    @cached_property
    def members(self) -> np.ndarray:
        """Indices, in the vector the cones act on, of every entry in some cone."""
        if self.count == 0:
            return np.zeros(0, dtype=np.int64)
        blocks = zip(self.offset, self.dim, strict=True)
        return np.concatenate([np.arange(o, o + d) for o, d in blocks])

    def same_blocks(self, other: ConeArrays) -> bool:
        """Same kinds, offsets and sizes as ``other`` (friction coefficients and normals
        may differ)."""
        return self is other or (
            self.kind.tobytes() == other.kind.tobytes()
            and self.offset.tobytes() == other.offset.tobytes()
            and self.dim.tobytes() == other.dim.tobytes()
        )

    def relocated(self, offset: np.ndarray) -> ConeArrays:
        """The same cones with new block offsets."""
        return ConeArrays(self.kind, offset.astype(np.int64), self.dim, self.mu, self.normal)


def _integer(value: object, what: str) -> int:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{what} must be an integer, got {value!r}")
    return int(value)


def _check_friction(cone: FrictionCone, index: int) -> np.ndarray:
    mu = cone.mu
    if isinstance(mu, (bool, np.bool_)) or not isinstance(
        mu, (int, float, np.integer, np.floating)
    ):
        raise TypeError(f"cones[{index}].mu must be a real number, got {mu!r}")
    if not math.isfinite(mu) or mu <= 0:
        raise ValueError(f"cones[{index}].mu must be finite and > 0, got {mu}")
    if cone.normal is None:
        return np.array([0.0, 0.0, 1.0])
    normal = np.asarray(cone.normal)
    if normal.dtype.kind not in "iuf":
        raise TypeError(
            f"cones[{index}].normal must be 3 real numbers, got {cone.normal!r}"
        )
    normal = normal.astype(np.float64)
    if normal.shape != (3,):
        raise ValueError(f"cones[{index}].normal must have 3 entries, got shape {normal.shape}")
    if not np.all(np.isfinite(normal)):
        raise ValueError(f"cones[{index}].normal contains NaN or inf")
    norm = float(np.linalg.norm(normal))
    if abs(norm - 1.0) > _UNIT_TOLERANCE:
        raise ValueError(f"cones[{index}].normal must be a unit vector, its norm is {norm:.6g}")
    return normal / norm


def _flat_friction(cone: FrictionCone, index: int) -> tuple[int, float, np.ndarray | None]:
    normal = _check_friction(cone, index)
    return 3, float(cone.mu), normal


def _flat_second_order(cone: SecondOrderCone, index: int) -> tuple[int, float, np.ndarray | None]:
    size = _integer(cone.dim, f"cones[{index}].dim")
    if size < 2:
        raise ValueError(f"cones[{index}].dim must be >= 2, got {size}")
    return size, 0.0, None


@dataclass(frozen=True)
class ConeKind:
    """One cone kind of the registry :data:`KINDS`."""

    code: int
    """Its code in :attr:`ConeArrays.kind`, the same as the compiled core's."""
    spec: type
    """The user-facing spec class."""
    flatten: Callable[[object, int], tuple[int, float, np.ndarray | None]]
    """``(size, mu, normal)`` of a spec, which is ``cones[index]``, validated (raising
    the error that names it); ``normal`` ``None`` for none (a zero row)."""


KINDS: tuple[ConeKind, ...] = (
    ConeKind(FRICTION, FrictionCone, _flat_friction),
    ConeKind(SECOND_ORDER, SecondOrderCone, _flat_second_order),
)
"""The cone kinds, in the order of their codes."""

_SPECS = tuple(kind.spec for kind in KINDS)
_NAMES = " or ".join(spec.__name__ for spec in _SPECS)


def cone_tuple(cones: Cone | Sequence[Cone]) -> tuple[Cone, ...]:
    """``cones`` as a tuple: a single spec becomes a one-element tuple.

    Raises
    ------
    TypeError
        If ``cones`` is neither a spec of one of the :data:`KINDS` nor an iterable
        (a string is not).
    """
    if type(cones) is tuple:
        return cones
    if isinstance(cones, _SPECS):
        return (cones,)
    if isinstance(cones, (str, bytes)) or not isinstance(cones, Iterable):
        raise TypeError(f"cones must be a sequence of {_NAMES}, got {cones!r}")
    return tuple(cones)


def flatten_cones(cones: Sequence[Cone], n: int) -> ConeArrays:
    """Validate cone specs for an ``n``-vector and return them as flat arrays.

    Results are memoized for hashable inputs, keyed on the specs' values and the types
    of their fields (:func:`fccqp.fast_checks.cone_key`): a control loop passes the
    same cones every tick, and a spec that only compares equal to a valid one is still
    validated.

    Raises
    ------
    TypeError
        If ``cones`` is not a sequence of cones, an entry is not a spec of one of the
        :data:`KINDS` (:class:`FrictionCone`, :class:`SecondOrderCone`), or a field has
        the wrong type.
    ValueError
        If a block leaves ``[0, n)``, overlaps another block, a second-order cone has
        ``dim < 2``, or a friction cone has a bad ``mu`` or normal.
    """
    if type(cones) is not tuple:   # a tuple, the control loop's case, needs no checks
        cones = cone_tuple(cones)
    try:
        flat = _MEMO.get(key := cone_key(cones, n))
    except TypeError:  # unhashable field, e.g. a numpy normal: validate uncached
        return _flatten(cones, n)
    if flat is None:
        flat = _flatten(cones, n)
        if len(_MEMO) >= MEMO_SIZE:
            _MEMO.clear()
        _MEMO[key] = flat
    return flat


MEMO_SIZE = 64
"""Most cone lists :func:`flatten_cones` remembers (all are forgotten when full)."""
_MEMO: dict[tuple, ConeArrays] = {}


def _flatten(cones: tuple[Cone, ...], n: int) -> ConeArrays:
    arrays = upright_friction_arrays(cones, n)
    if arrays is not None:   # the control loops' specs, checked in compiled code
        return ConeArrays(*arrays)
    k = len(cones)
    kind = np.zeros(k, dtype=np.int64)
    offset = np.zeros(k, dtype=np.int64)
    dim = np.zeros(k, dtype=np.int64)
    mu = np.zeros(k)
    normal = np.zeros((k, 3))
    for i, cone in enumerate(cones):
        for entry in KINDS:
            if isinstance(cone, entry.spec):
                break
        else:
            raise TypeError(f"cones[{i}] must be a {_NAMES}, got {type(cone).__name__}")
        size, mu[i], row = entry.flatten(cone, i)
        kind[i] = entry.code
        if row is not None:
            normal[i] = row
        start = _integer(cone.start, f"cones[{i}].start")
        if start < 0 or start + size > n:  # Python ints: no overflow before the check
            raise ValueError(
                f"cones[{i}] covers x[{start}:{start + size}], outside x of length {n}"
            )
        offset[i], dim[i] = start, size
    order = np.argsort(offset, kind="stable")
    for a, b in zip(order[:-1], order[1:], strict=True):
        if offset[a] + dim[a] > offset[b]:
            raise ValueError(
                f"cones[{a}] (x[{offset[a]}:{offset[a] + dim[a]}]) overlaps "
                f"cones[{b}] (x[{offset[b]}:{offset[b] + dim[b]}])"
            )
    for array in (kind, offset, dim, mu, normal):
        array.flags.writeable = False  # memoized and shared: nobody may write into it
    return ConeArrays(kind, offset, dim, mu, normal)
