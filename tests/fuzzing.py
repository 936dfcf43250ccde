"""Seeded fuzzer over the failure classes of issue 26, "Honest verdicts on every problem".

Every class is a generator ``rng -> scenario`` (:data:`CLASSES`); a :class:`Case` is a
class name and a seed, so ``Case.of("feasible", 17)`` rebuilds the same scenario on
any machine, and :func:`judge` says whether fccqp, on one KKT backend, answered it
honestly. A failure is

- ``exception``: an exception other than the documented ``ValueError`` / ``TypeError``
  naming the argument (docs/api.md, Errors), or such an error on valid data
  (``rejected``), or none on malformed data (``accepted``);
- ``verify``: a point or certificate that :func:`verify.check_solution` rejects for its
  status (infeasibility statuses through their certificate conditions);
- ``stalled``: ``MAX_ITER_REACHED`` or ``NUMERICAL_ERROR`` where Clarabel at tight
  tolerance (:func:`reference.clarabel_solve`) returns a solution or a certificate;
- ``status``: ``SOLVED`` where Clarabel says infeasible or unbounded, or an
  infeasibility claim where Clarabel finds an optimum (``SOLVED_INACCURATE`` promises
  only residuals within 10x the tolerances, which a problem infeasible by less can
  meet: verified, not compared);
- ``reuse``: a :class:`fccqp.Solver` that accepts what a fresh solve rejects, or the
  other way round.

Clarabel is the reference only where it agrees with what the construction proves
(a KKT point, a Farkas certificate, a ray): when the two differ, the case has no
reference and :attr:`Verdict.conflict` says so, so a generator bug or a Clarabel miss
is counted apart and never blamed on fccqp. Nor is an optimum that no double-precision
point can be verified at (:func:`_below_rounding`) a reference for a stall. The
description of a failure starts with its kind (``"verify: ..."``);
``tools/fuzz_campaign.py`` runs many cases and ``tests/test_fuzz.py`` a fixed subset.
"""

from __future__ import annotations

import re
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np
import scipy.sparse as sp
from scipy.linalg import null_space

import fccqp
from fccqp import FrictionCone, SecondOrderCone, Status
from fccqp.settings import KKT_BACKENDS
from reference import clarabel_solve, tangent_basis
from verify import Problem, Tolerances, check_solution, from_qpsolvers

ANSWERS = ("solved", "primal_infeasible", "dual_infeasible")
"""Conclusive reference statuses (Clarabel's, in :mod:`reference`'s names)."""
STALLED = (Status.MAX_ITER_REACHED, Status.NUMERICAL_ERROR)
"""Statuses that give up: a failure where the reference has an answer."""
MAX_N = 20
"""Most variables of a generated problem."""
MAX_M = 8
"""Most equality rows of a generated problem."""


# --------------------------------------------------------------------------- scenarios


@dataclass(frozen=True)
class Native:
    """One call of ``fccqp.solve`` on a valid problem.

    ``truth`` is the status the construction proves (``None``: not known); ``form``
    says how the arrays are passed (``"dense"``, ``"sparse"`` for ``scipy.sparse``
    ``P`` and ``A``, ``"none"`` for ``None`` in place of absent parts, ``"views"`` for
    Fortran-ordered matrices and strided vectors, ``"sentinel"`` for absent bounds
    written ``-1e30`` and ``1e20``). With
    ``may_reject`` (extreme data) a ``ValueError`` / ``TypeError`` naming an argument
    is an honest answer too, unless it calls the PSD-by-construction ``P`` non-convex.
    """

    problem: Problem
    truth: str | None
    what: str
    form: str = "dense"
    may_reject: bool = False


@dataclass(frozen=True)
class BadInput:
    """A malformed call: ``fccqp.solve(*args, settings=settings, **overrides)``, or
    ``Solver(**overrides).solve(*args, x0=x0)`` when ``x0`` is given, must raise a
    ``ValueError`` or ``TypeError`` whose message names one of ``names``."""

    args: tuple
    names: tuple[str, ...]
    what: str
    overrides: dict = field(default_factory=dict)
    settings: object = None
    x0: object = None


@dataclass(frozen=True)
class Reuse:
    """Successive solves of one :class:`fccqp.Solver`, each judged like a fresh solve of
    the same data (the fresh solve decides whether an error is due). With ``in_place``
    every step is copied into the first step's arrays, which are passed again (the
    control loop's refill); otherwise each step passes new arrays. ``truths`` holds the
    status the construction proves for each step (``None``: not known; empty: none
    known), as :attr:`Native.truth` does."""

    steps: tuple[Problem, ...]
    in_place: bool
    what: str
    truths: tuple[str | None, ...] = ()


@dataclass(frozen=True)
class Qpsolvers:
    """``qpsolvers.solve_problem(problem, solver="fccqp")`` against ``solver="clarabel"``;
    the problem is feasible and bounded by construction."""

    problem: object
    what: str


@dataclass(frozen=True)
class Cvxpy:
    """A CVXPY problem solved with ``fccqp_cvxpy.FCCQP`` and with Clarabel: ``min 1/2
    ||M'x||^2 + q'x`` subject to ``A x == b``, ``G x <= h``, entrywise bounds and
    second-order cones ``||x[v] * scale|| <= x[t]`` (``cones``, mapped natively) or on
    affine expressions (``affine_cones``, slacks); feasible by construction."""

    M: np.ndarray
    q: np.ndarray
    A: np.ndarray
    b: np.ndarray
    G: np.ndarray
    h: np.ndarray
    lb: np.ndarray
    ub: np.ndarray
    cones: tuple[tuple[int, tuple[int, ...], float], ...]
    affine_cones: tuple[tuple[np.ndarray, float, np.ndarray, np.ndarray], ...]
    what: str


# ------------------------------------------------------------------------ building blocks


def _unit(rng: np.random.Generator, k: int) -> np.ndarray:
    v = rng.standard_normal(k)
    return v / np.linalg.norm(v)


def _tilted(rng: np.random.Generator, axis: np.ndarray, angle: float) -> np.ndarray:
    """A unit vector at ``angle`` radians from the unit ``axis``, in a random direction."""
    t = tangent_basis(axis).T @ _unit(rng, 2)
    return np.cos(angle) * axis + np.sin(angle) * t


def _log_uniform(rng: np.random.Generator, low: float, high: float) -> float:
    return float(10.0 ** rng.uniform(np.log10(low), np.log10(high)))


@dataclass(frozen=True)
class Layout:
    """Which entries of ``x`` are in cones, boxed (and how) or free: the structure of a
    generated problem. ``box`` maps an entry to ``"lower"``, ``"upper"``, ``"both"`` or
    ``"fixed"``; cone blocks and boxed entries are interleaved with free ones."""

    n: int
    cones: tuple
    lb: np.ndarray
    ub: np.ndarray
    box: dict
    free: tuple[int, ...]

    def axis(self, cone: FrictionCone | SecondOrderCone) -> tuple[np.ndarray, float]:
        """The cone's axis within its block and its opening ``mu`` (1 for a second-order
        cone, whose axis is the block's first entry)."""
        if isinstance(cone, FrictionCone):
            return np.asarray(cone.normal or (0.0, 0.0, 1.0)), float(cone.mu)
        axis = np.zeros(cone.dim)
        axis[0] = 1.0
        return axis, 1.0

    @property
    def members(self) -> frozenset:
        """The entries that belong to a cone block."""
        return frozenset(j for c in self.cones for j in range(c.start, c.start + c.dim))


def _friction(rng: np.random.Generator, start: int) -> FrictionCone:
    """A friction cone, about ``(0, 0, 1)`` or a normal tilted up to 60 degrees."""
    mu = float(rng.uniform(0.1, 2.0))
    if rng.random() < 0.5:
        return FrictionCone(start, mu)
    normal = _tilted(rng, np.array([0.0, 0.0, 1.0]), rng.uniform(0, np.pi / 3))
    return FrictionCone(start, mu, tuple(float(v) for v in normal))


def random_layout(rng: np.random.Generator, min_n: int = 1, max_n: int = MAX_N,
                  frictions: int | None = None, socs: int | None = None,
                  boxed: int | None = None, soc_dim: int | None = None) -> Layout:
    """A random structure of ``min_n`` to ``max_n`` entries: up to 3 friction cones, 2
    second-order cones of size 2-5, 8 boxed and 6 free entries unless the counts are
    given (boxed and free entries give way when the cones fill ``max_n``; ``soc_dim``
    fixes the size of every second-order cone), in a random order."""
    frictions = int(rng.integers(0, 4)) if frictions is None else frictions
    socs = int(rng.integers(0, 3)) if socs is None else socs
    boxed = int(rng.integers(0, 9)) if boxed is None else boxed
    units = [("friction", 3)] * frictions
    units += [("soc", soc_dim or int(rng.integers(2, 6))) for _ in range(socs)]
    room = max_n - sum(size for _, size in units)
    boxed = min(boxed, room)
    free = max(min(int(rng.integers(0, 7)), room - boxed), min_n - (max_n - room) - boxed)
    units += [("box", 1)] * boxed + [("free", 1)] * free
    order = rng.permutation(len(units))
    n = sum(size for _, size in units)
    lb, ub = np.full(n, -np.inf), np.full(n, np.inf)
    cones, box, free_entries, start = [], {}, [], 0
    for kind, size in (units[k] for k in order):
        if kind == "friction":
            cones.append(_friction(rng, start))
        elif kind == "soc":
            cones.append(SecondOrderCone(start, size))
        elif kind == "box":
            side = ("lower", "upper", "both", "fixed")[rng.integers(4)]
            low = rng.uniform(-2, 1)
            high = low + rng.uniform(0.1, 3)
            lb[start] = low if side in ("lower", "both", "fixed") else -np.inf
            ub[start] = high if side in ("upper", "both") else low if side == "fixed" else np.inf
            box[start] = side
        else:
            free_entries.append(start)
        start += size
    return Layout(n, tuple(cones), lb, ub, box, tuple(free_entries))


def interior_point(rng: np.random.Generator, layout: Layout) -> np.ndarray:
    """A point strictly inside every cone and box (at the value of a fixed entry)."""
    x = rng.standard_normal(layout.n)
    for cone in layout.cones:
        axis, mu = layout.axis(cone)
        block = slice(cone.start, cone.start + axis.size)
        s = rng.uniform(0.2, 2.0)
        x[block] = s * (axis + mu * rng.uniform(0, 0.9) * _tangent(rng, axis))
    for j in layout.box:
        low, high = layout.lb[j], layout.ub[j]
        if np.isfinite(low) and np.isfinite(high):
            x[j] = low + rng.uniform(0.1, 0.9) * (high - low)
        elif np.isfinite(low):
            x[j] = low + rng.uniform(0.1, 2)
        else:
            x[j] = high - rng.uniform(0.1, 2)
    return x


def _tangent(rng: np.random.Generator, axis: np.ndarray) -> np.ndarray:
    """A random unit vector orthogonal to the unit ``axis``."""
    v = rng.standard_normal(axis.size)
    v -= (v @ axis) * axis
    return v / np.linalg.norm(v)


def kkt_point(rng: np.random.Generator, layout: Layout) -> tuple[np.ndarray, np.ndarray]:
    """A primal point and box/cone multipliers that are complementary: each cone block
    inside (``z = 0``), at its apex (``-z`` in the dual cone) or on its boundary (``-z``
    on the dual cone's boundary, orthogonal to the block); each boxed entry between its
    bounds or at one with a multiplier of the right sign, sometimes zero (weakly
    active). With ``q = -(P x + A'y + z)`` and ``b = A x`` the point is optimal."""
    x = interior_point(rng, layout)
    z = np.zeros(layout.n)
    weight = lambda: 0.0 if rng.random() < 0.15 else rng.uniform(0.1, 3.0)  # noqa: E731
    for cone in layout.cones:
        axis, mu = layout.axis(cone)
        block = slice(cone.start, cone.start + axis.size)
        t = _tangent(rng, axis)
        where = rng.integers(3)
        if where == 1:  # apex: -z in the dual cone (opening 1/mu), on its boundary or inside
            x[block] = 0.0
            z[block] = -weight() * (axis + rng.choice([1.0, rng.uniform(0, 1)]) * t / mu)
        elif where == 2:  # boundary: x = s (n + mu t), -z = c (n - t / mu)
            x[block] = rng.uniform(0.2, 2.0) * (axis + mu * t)
            z[block] = -weight() * (axis - t / mu)
    for j, side in layout.box.items():
        at = rng.integers(3)
        if side == "fixed":
            z[j] = rng.standard_normal()
        elif at == 1 and side in ("lower", "both"):
            x[j], z[j] = layout.lb[j], -weight()
        elif at == 2 and side in ("upper", "both"):
            x[j], z[j] = layout.ub[j], weight()
    return x, z


def psd(rng: np.random.Generator, n: int, rank: int | None = None) -> np.ndarray:
    """A PSD matrix of the given (or a random) rank with a random null space, entries of
    size 1e-2 to 1e2; a quarter of the time diagonal instead (zero columns)."""
    rank = int(rng.integers(0, n + 1)) if rank is None else rank
    scale = 10.0 ** rng.uniform(-2, 2)
    if rng.random() < 0.25:
        d = np.zeros(n)
        d[rng.permutation(n)[:rank]] = rng.uniform(0.1, 3, rank)
        return scale * np.diag(d)
    M = rng.standard_normal((n, rank))
    return scale * (M @ M.T) / max(rank, 1)


def rows(rng: np.random.Generator, m: int, n: int) -> np.ndarray:
    """``m`` random rows of random scales (1e-1 to 1e1); a third of the time some of
    them are combinations of the others (rank-deficient, to be given consistent ``b``)."""
    A = rng.standard_normal((m, n)) * 10.0 ** rng.uniform(-1, 1, (m, 1))
    if m >= 2 and rng.random() < 0.33:
        base = int(rng.integers(1, m))
        A[base:] = rng.standard_normal((m - base, base)) @ A[:base]
    return A


def _random_m(rng: np.random.Generator) -> int:
    return int(rng.integers(0, MAX_M + 1))


def _form(rng: np.random.Generator) -> str:
    return str(rng.choice(["dense", "dense", "sparse", "none", "views"]))


# ------------------------------------------------------------------------- the classes


def bad_input(rng: np.random.Generator) -> BadInput:
    """Class 1: a valid problem with one thing wrong (a shape, a NaN or inf, an object
    or complex array, a non-square or asymmetric or non-convex ``P``, an entry beyond
    1e20, a cone out of range, overlapping or ill-specified, a bound on a cone entry, a
    bad ``x0`` or setting). The documented answer is a ``ValueError`` or ``TypeError``
    naming the argument."""
    layout = random_layout(rng, min_n=2, frictions=int(rng.integers(1, 3)))
    n = layout.n
    x, z = kkt_point(rng, layout)
    P = psd(rng, n)
    m = int(rng.integers(1, MAX_M + 1))
    A = rows(rng, m, n)
    args = {"P": P, "q": -(P @ x + A.T @ rng.standard_normal(m) + z), "A": A, "b": A @ x,
            "lb": layout.lb.copy(), "ub": layout.ub.copy(), "cones": list(layout.cones)}
    corruption = _CORRUPTIONS[int(rng.integers(len(_CORRUPTIONS)))]
    names, what, extra = corruption(rng, args, layout)
    if rng.random() < 0.3:   # the sparse conversion checks the matrices its own way
        for name in ("P", "A"):
            value = args[name]
            if isinstance(value, np.ndarray) and value.ndim == 2 and value.dtype.kind == "f":
                args[name] = sp.csc_matrix(value)
        what += " (scipy.sparse P, A)"
    call = (args["P"], args["q"], args["A"], args["b"], args["lb"], args["ub"], args["cones"])
    return BadInput(call, names, what, **extra)


def _entry(rng: np.random.Generator, array: np.ndarray) -> tuple[int, ...]:
    return tuple(int(rng.integers(s)) for s in array.shape)


def _bad_shape(rng, args, layout):
    name = str(rng.choice(["P", "P1d", "P3d", "ragged", "q", "q2d", "A", "b", "lb", "ub",
                           "Ab", "bA"]))
    P, n = args["P"], layout.n
    if name == "P":
        args["P"] = P[:, :-1] if rng.random() < 0.5 else np.hstack([P, P[:, :1]])
        return ("P",), "P not square", {}
    if name == "P1d":
        args["P"] = P.ravel()
        return ("P",), "P one-dimensional", {}
    if name == "P3d":
        args["P"] = P[None]
        return ("P",), "P three-dimensional", {}
    if name == "q2d":
        args["q"] = np.tile(args["q"][:, None], (1, 2))
        return ("q",), "q a matrix", {}
    if name == "ragged":
        rows_ = [list(row) for row in P]
        rows_[int(rng.integers(n))].append(0.0)
        args["P"] = rows_
        return ("P",), "P a ragged list of lists", {}
    if name == "Ab":
        args["b"] = None
        return ("A", "b"), "A without b", {}
    if name == "bA":
        args["A"] = None
        return ("A", "b"), "b without A", {}
    if name == "A":
        args["A"] = args["A"][:, : n - 1] if rng.random() < 0.5 else np.hstack(
            [args["A"], args["A"][:, :1]])
        return ("A",), "A with the wrong number of columns", {}
    vector = args[name]
    args[name] = vector[:-1] if rng.random() < 0.5 else np.append(vector, 0.0)
    return (name,), f"{name} of the wrong length", {}


def _not_finite(rng, args, layout):
    name = str(rng.choice(["P", "q", "A", "b", "lb", "ub"]))
    value = float(rng.choice([np.nan, np.inf, -np.inf])) if name not in ("lb", "ub") else np.nan
    array = args[name].copy()
    index = _entry(rng, array)
    array[index] = value
    if name == "P":
        array[index[::-1]] = value
    args[name] = array
    return (name,), f"{value} in {name}", {}


def _too_large(rng, args, layout):
    name = str(rng.choice(["P", "q", "A", "b"]))
    array = args[name].copy()
    index = _entry(rng, array)
    array[index] = float(rng.choice([-1, 1])) * _log_uniform(rng, 2e20, 1e300)
    if name == "P":
        array[index[::-1]] = array[index]
    args[name] = array
    return (name,), f"an entry of {name} beyond 1e20", {}


def _bad_bounds(rng, args, layout):
    free = [j for j in range(layout.n) if j not in layout.members]
    j = int(rng.choice(free)) if free else None
    kind = int(rng.integers(4)) if j is not None else 3
    if kind == 0:
        args["lb"][j], args["ub"][j] = 1.0, rng.uniform(-1, 0.99)
        return ("lb", "ub"), "lb > ub", {}
    if kind == 1:
        args["lb"][j] = np.inf
        return ("lb",), "lb = +inf", {}
    if kind == 2:
        args["ub"][j] = -np.inf
        return ("ub",), "ub = -inf", {}
    cone = args["cones"][0]
    name = str(rng.choice(["lb", "ub"]))
    args[name][cone.start + int(rng.integers(cone.dim))] = rng.uniform(-1, 1)
    return ("lb", "ub", "cones"), f"a finite {name} on a cone entry", {}


def _bad_dtype(rng, args, layout):
    name = str(rng.choice(["P", "q", "A", "b", "lb", "ub"]))
    kind = int(rng.integers(3))
    array = args[name]
    if kind == 0:
        args[name] = array.astype(object)
        what = "an object array"
    elif kind == 1:
        args[name] = array.astype(object)
        args[name][_entry(rng, array)] = str(rng.choice(["x", "1.0", "None"]))
        what = "an object array holding a string"
    else:
        args[name] = array + 1j * (rng.random(array.shape) < 0.5)
        what = "a complex array"
    return (name,), f"{name} {what}", {}


def _bad_matrix(rng, args, layout):
    P, n = args["P"].copy(), layout.n
    kind = int(rng.integers(3))
    if kind == 0:
        i, j = rng.choice(n, 2, replace=False)
        P[i, j] += _log_uniform(rng, 1e-8, 1) * max(np.abs(P).max(), 1.0)
        args["P"] = P
        return ("P",), "P asymmetric", {}
    A = args["A"]
    if kind == 1 or np.linalg.matrix_rank(A) == n:
        v = _unit(rng, n)
        args["A"], args["b"] = None, None
        what = "P with a negative eigenvalue and no rows"
    else:  # negative curvature along a direction that the rows leave free
        v = _unit(rng, n - np.linalg.matrix_rank(A)) @ null_space(A).T
        what = "P with negative curvature on the null space of A"
    curvature = _log_uniform(rng, 1e-4, 10) * max(1.0, np.abs(P).max())
    args["P"] = P - (v @ P @ v + curvature) * np.outer(v, v)
    return ("P",), f"{what} ({-curvature:.2g})", {}


def _bad_cones(rng, args, layout):
    cones, n = args["cones"], layout.n
    k = int(rng.integers(len(cones)))
    cone = cones[k]
    kind = int(rng.integers(9))
    if kind == 0:
        cones.append(SecondOrderCone(cone.start + int(rng.integers(cone.dim)), 2))
        what = "overlapping cones"
    elif kind == 1:
        cones[k] = replace(cone, start=int(rng.choice([-1, n - cone.dim + 1, n + 5])))
        what = "a cone out of range"
    elif kind == 2 and isinstance(cone, FrictionCone):
        cones[k] = replace(cone, mu=[0.0, -0.5, np.nan, np.inf, 1j, "0.5"][rng.integers(6)])
        what = f"mu = {cones[k].mu!r}"
    elif kind == 3 and isinstance(cone, FrictionCone):
        cones[k] = replace(cone, normal=[(0, 0, 2.0), (0, 1.0), (np.nan, 0, 1), ("a", 0, 1),
                                         (0, 0, 1 + 1e-6)][int(rng.integers(5))])
        what = f"normal = {cones[k].normal!r}"
    elif kind == 4:
        cones[k] = replace(cone, start=float(cone.start))
        what = "a float start"
    elif kind == 5:
        cones[k] = SecondOrderCone(cone.start, int(rng.choice([1, 0, -2])))
        what = f"a second-order cone of dim {cones[k].dim}"
    elif kind == 6:
        cones[k] = (cone.start, 3)
        what = "a tuple for a cone"
    elif kind == 7:
        args["cones"] = [3, "cones", 1.5][rng.integers(3)]
        what = f"cones = {args['cones']!r}"
    else:
        cones[k] = SecondOrderCone(cone.start, 2.5)
        what = "a float dim"
    return ("cones",), what, {}


_BAD_SETTINGS = (
    ("rho", 0.0), ("rho", -1.0), ("rho", np.nan), ("rho", np.inf), ("sigma", 0.0),
    ("alpha", 0.0), ("alpha", 2.0), ("eps_abs", -1e-5), ("eps_rel", np.inf),
    ("eps_prim_inf", 0.0), ("eps_dual_inf", -1.0), ("max_iter", 0), ("max_iter", 1.5),
    ("max_iter", 2**31), ("min_iter", -1), ("time_limit", 0.0), ("time_limit", np.nan),
    ("check_termination", 0), ("adaptive_rho", "yes"), ("adaptive_rho_interval", 0),
    ("adaptive_rho_tolerance", 1.0), ("anderson_memory", -1), ("anderson_memory", 101),
    ("scaling", 101), ("polish_refine_iter", 101), ("kkt_backend", "dense"),
    ("kkt_backend", None), ("verbose", 1), ("polish", None), ("rho", "0.1"),
    ("rho", True), ("sigma", 1e-6 + 0j), ("rhoo", 0.1), ("warm_start", "no"),
)


def _bad_setting(rng, args, layout):
    kind = int(rng.integers(len(_BAD_SETTINGS) + 3))
    if kind == len(_BAD_SETTINGS):
        return ("eps_abs", "eps_rel"), "eps_abs = eps_rel = 0", {
            "overrides": {"eps_abs": 0.0, "eps_rel": 0.0}}
    if kind == len(_BAD_SETTINGS) + 1:
        return ("settings",), "settings of the wrong type", {"settings": {"rho": 0.1}}
    if kind == len(_BAD_SETTINGS) + 2:
        x0 = [np.full(layout.n + 1, 0.0), np.full(layout.n, np.nan),
              np.full(layout.n, 1e21), np.array(["a"] * layout.n, dtype=object),
              np.zeros(layout.n, complex)][int(rng.integers(5))]
        return ("x0",), f"x0 = {x0!r}", {"x0": x0}
    name, value = _BAD_SETTINGS[kind]
    return (name,), f"setting {name} = {value!r}", {"overrides": {name: value}}


_CORRUPTIONS = (_bad_shape, _not_finite, _too_large, _bad_bounds, _bad_dtype, _bad_matrix,
                _bad_cones, _bad_setting)


def feasible(rng: np.random.Generator) -> Native:
    """Class 2: a problem with a known optimum (:func:`kkt_point`): boxes with
    active and weakly active bounds, equalities (sometimes rank-deficient, consistent),
    friction and second-order cones inside, at the apex or on the boundary, ``P`` PSD
    and often singular."""
    layout = random_layout(rng)
    n = layout.n
    x, z = kkt_point(rng, layout)
    P, A = psd(rng, n), rows(rng, _random_m(rng), n)
    q = -(P @ x + A.T @ rng.standard_normal(A.shape[0]) + z)
    problem = Problem.of(P, q, A, A @ x, layout.lb, layout.ub, layout.cones)
    return Native(problem, "solved", f"KKT point, n={n} m={A.shape[0]}", _form(rng))


def primal_infeasible(rng: np.random.Generator) -> Native:
    """Class 3: infeasible by construction, each with its Farkas certificate in mind:
    inconsistent rows, a row out of the box's reach, a friction or second-order cone
    pinned outside itself by rows (the whole block, or only ``n'f = s`` and ``t'f = mu s
    (1 + gap)`` as in ``fz = 1, fx = mu (1 + gap)``), several cones whose sum must hit a
    point outside the sum of the cones, and a friction cone capped through a boxed copy
    of its normal force. The gap is 1e-4 to 1 of the data; other rows, consistent with
    a point that meets the pinning rows, are added. Half of the time ``P`` has full
    rank; otherwise the problem may also be unbounded (then either certificate is an
    honest answer, and Clarabel gives one of them)."""
    kind = str(rng.choice(["rows", "box", "cone", "cones", "soc", "socs", "capped"]))
    gap = _log_uniform(rng, 1e-4, 1.0)
    frictions = {"cone": 1, "capped": 1, "cones": int(rng.integers(2, 4)), "socs": 0}.get(
        kind, 0) + int(kind not in ("cones", "socs") and rng.random() < 0.5)
    socs = {"soc": 1, "socs": int(rng.integers(2, 4)), "cones": 0}.get(kind, 0) + int(
        kind not in ("cones", "socs") and rng.random() < 0.5)
    layout = random_layout(rng, max_n=MAX_N - (kind == "capped"), frictions=frictions,
                           socs=min(socs, 3), boxed=int(rng.integers(kind == "box", 7)),
                           soc_dim=int(rng.integers(2, 5)) if kind == "socs" else None)
    axis = _tilted(rng, np.array([0.0, 0.0, 1.0]), rng.uniform(0, 0.5))
    if kind == "cones":
        layout = _aligned_frictions(rng, layout, axis)
    n = layout.n
    x = interior_point(rng, layout)
    if kind == "rows":
        A = rows(rng, int(rng.integers(1, MAX_M)), n)
        combo = rng.standard_normal(A.shape[0])
        A = np.vstack([A, combo @ A])
        b = A @ x
        b[-1] += gap * rng.choice([-1, 1]) * max(1.0, np.abs(combo) @ np.abs(A[:-1] @ x))
        what = "inconsistent rows"
    elif kind == "box":
        A, b = _out_of_reach(rng, layout, gap)
        what = "a row out of the box's reach"
    elif kind in ("cone", "soc"):
        cone = next(c for c in layout.cones if isinstance(c, FrictionCone) == (kind == "cone"))
        A, b, x = _pinned_outside(rng, layout, [cone], x, gap, axis)
        what = f"a {type(cone).__name__} pinned outside itself by {A.shape[0]} rows"
    elif kind in ("cones", "socs"):
        group = [c for c in layout.cones if isinstance(c, FrictionCone) == (kind == "cones")]
        A, b, x = _pinned_outside(rng, layout, group, x, gap, axis)
        what = f"{len(group)} cones whose sum is pinned outside their sum"
    else:
        A, b, x, layout = _capped(rng, layout, x, gap)
        what = "a friction cone capped through a boxed copy of its normal force"
    extra = rows(rng, int(rng.integers(0, MAX_M - A.shape[0] + 1)), layout.n)
    A, b = np.vstack([A, extra]), np.concatenate([b, extra @ x])
    rank = layout.n if rng.random() < 0.5 else None   # full rank: no ray, not unbounded too
    problem = Problem.of(psd(rng, layout.n, rank), rng.standard_normal(layout.n), A, b,
                         layout.lb, layout.ub, layout.cones)
    return Native(problem, "primal_infeasible", f"{what}, gap {gap:.2g}", _form(rng))


def _aligned_frictions(rng: np.random.Generator, layout: Layout, axis: np.ndarray) -> Layout:
    """The layout with its friction cones' normals within 0.9 of their half-angle
    ``atan(1/mu)`` of ``axis``, which then lies inside every dual cone."""
    cones = tuple(
        replace(c, normal=tuple(float(v) for v in _tilted(
            rng, axis, rng.uniform(0, 0.9) * np.arctan(1 / c.mu))))
        if isinstance(c, FrictionCone) else c for c in layout.cones)
    return replace(layout, cones=cones)


def _out_of_reach(rng: np.random.Generator, layout: Layout,
                  gap: float) -> tuple[np.ndarray, np.ndarray]:
    """One row over boxed entries whose right-hand side lies beyond the row's maximum
    over the box (each coefficient's sign picks a finite side)."""
    a = np.zeros(layout.n)
    for j, side in layout.box.items():
        sign = {"lower": -1.0, "upper": 1.0}.get(side, rng.choice([-1.0, 1.0]))
        a[j] = sign * rng.uniform(0.2, 3)
    used = a != 0
    side = np.where(a > 0, layout.ub, layout.lb)[used]   # the finite side each sign picks
    reach = float(a[used] @ side)
    size = max(1.0, float(np.abs(a[used]) @ np.abs(side)))
    return a[None], np.array([reach + gap * size])


def _pinned_outside(rng: np.random.Generator, layout: Layout, group: list, x: np.ndarray,
                    gap: float, axis: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rows that pin the blocks of ``group`` (cones of one size) outside what they can
    reach, and ``x`` changed to meet them (so that rows added later stay consistent).

    One cone: its block is pinned ``gap`` beyond its boundary, ``s (n + mu (1 + gap)
    t)``, either whole or only along ``n`` and ``t``. Several friction cones (normals
    around ``axis``, which lies in every dual cone): their sum is pinned to ``w`` with
    ``axis'w = -gap``. Several second-order cones: the ``t`` parts sum to ``s``, the
    ``v`` parts to ``s (1 + gap) u``."""
    size = group[0].dim
    cone_axis, mu = layout.axis(group[0])
    t = _tangent(rng, cone_axis)
    s = rng.uniform(0.2, 2)
    if len(group) > 1 and isinstance(group[0], FrictionCone):
        w = -gap * axis + rng.uniform(0.5, 3) * _tangent(rng, axis)
    else:
        w = s * (cone_axis + mu * (1 + gap) * t)
    if len(group) == 1 and rng.random() < 0.5:
        pins = np.vstack([cone_axis, t])
    else:
        pins = np.eye(size)
    A = np.zeros((pins.shape[0], layout.n))
    x = x.copy()
    for cone in group:
        A[:, cone.start:cone.start + size] = pins
        x[cone.start:cone.start + size] = 0.0
    x[group[0].start:group[0].start + size] = w
    return A, A @ x, x


def _capped(rng: np.random.Generator, layout: Layout, x: np.ndarray,
            gap: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, Layout]:
    """A boxed entry ``s`` in ``[0, cap]`` tied to a friction cone's normal force (``s =
    n'f``) and a row asking a tangential force ``mu cap (1 + gap)``: infeasible through
    the box and the cone together. ``s`` is appended to the layout."""
    cone = next(c for c in layout.cones if isinstance(c, FrictionCone))
    axis, mu = layout.axis(cone)
    cap = rng.uniform(0.5, 3)
    n = layout.n + 1
    lb, ub = np.append(layout.lb, 0.0), np.append(layout.ub, cap)
    layout = replace(layout, n=n, lb=lb, ub=ub, box={**layout.box, n - 1: "both"})
    t = _tangent(rng, axis)
    block = slice(cone.start, cone.start + 3)
    A = np.zeros((2, n))
    A[0, block], A[0, n - 1] = axis, -1.0
    A[1, block] = t
    x = np.append(x, cap)
    x[block] = cap * axis + mu * cap * (1 + gap) * t
    return A, A @ x, x, layout


def dual_infeasible(rng: np.random.Generator) -> Native:
    """Class 4: feasible and unbounded along a ray ``d`` by construction: ``P d = 0``
    (``P`` projected off ``d``, so its null space is rotated unless ``d`` is a
    coordinate), ``A d = 0``, ``q'd < 0`` by 5 % to 100 % of ``|q||d|``, and ``d`` in
    the recession cone: a free coordinate (a zero column of ``P``), a half-line of a
    one-sided box entry, a ray inside or on the boundary of a friction or second-order
    cone, or a combination of free, one-sided and cone entries."""
    kind = str(rng.choice(["free", "half-line", "friction", "soc", "combination"]))
    layout = random_layout(rng, max_n=MAX_N - 1,
                           frictions=int(kind == "friction") + int(rng.integers(0, 2)),
                           socs=int(kind == "soc") + int(rng.integers(0, 2)),
                           boxed=int(kind == "half-line") + int(rng.integers(0, 5)))
    if kind in ("free", "combination") and not layout.free:
        n = layout.n
        layout = replace(layout, n=n + 1, lb=np.append(layout.lb, -np.inf),
                         ub=np.append(layout.ub, np.inf), free=(n,))
    one_sided = [j for j, s in layout.box.items() if s in ("lower", "upper")]
    if kind == "half-line" and not one_sided:
        j = next(iter(layout.box))
        layout.ub[j], layout.box[j] = np.inf, "lower"
        one_sided = [j]
    n = layout.n
    d = np.zeros(n)
    if kind == "free":
        d[rng.choice(layout.free)] = 1.0
    elif kind == "half-line":
        j = int(rng.choice(one_sided))
        d[j] = 1.0 if layout.box[j] == "lower" else -1.0
    elif kind in ("friction", "soc"):
        cone = next(c for c in layout.cones if isinstance(c, FrictionCone) == (
            kind == "friction"))
        _ray_in(rng, layout, cone, d)
    else:
        for j in layout.free:
            d[j] = rng.standard_normal()
        for j in one_sided:
            d[j] = rng.uniform(0, 1) * (1.0 if layout.box[j] == "lower" else -1.0)
        for cone in layout.cones:
            if rng.random() < 0.5:
                _ray_in(rng, layout, cone, d)
    d /= np.linalg.norm(d)
    x = interior_point(rng, layout)
    off_d = np.eye(n) - np.outer(d, d)
    P = off_d @ psd(rng, n) @ off_d
    A = rows(rng, _random_m(rng), n) @ off_d
    q = rng.standard_normal(n)
    q -= (q @ d + rng.uniform(0.05, 1) * np.linalg.norm(q - (q @ d) * d) + 0.05) * d
    problem = Problem.of(P, q, A, A @ x, layout.lb, layout.ub, layout.cones)
    what = f"a ray ({kind}) along {np.count_nonzero(d)} entries"
    return Native(problem, "dual_infeasible", what, _form(rng))


def _ray_in(rng: np.random.Generator, layout: Layout, cone, d: np.ndarray) -> None:
    """Write into ``d`` a ray of ``cone``: inside it or, a third of the time, on its
    boundary."""
    axis, mu = layout.axis(cone)
    opening = 1.0 if rng.random() < 0.33 else rng.uniform(0, 0.95)
    d[cone.start:cone.start + axis.size] = axis + mu * opening * _tangent(rng, axis)


def solver_reuse(rng: np.random.Generator) -> Reuse:
    """Class 5: one ``fccqp.Solver`` over successive problems of one structure: made
    non-convex (``P[0, 0] = -0.53``, the rest of row and column 0 zero; a fresh solve
    raises the documented error unless the rows fix ``x[0]``) and back; new ``A``, ``q``
    and ``b``; the data rescaled by 1e-8 to 1e8; ``q`` turned along a ray; ``b`` made
    infeasible; the bounds moved. Half of the scenarios refill the first arrays in
    place."""
    kind = str(rng.choice(["nonconvex", "new rows", "rescaled", "unbounded", "infeasible",
                           "bounds"]))
    layout = random_layout(rng, min_n=2)
    n = layout.n
    P = psd(rng, n)
    A = rows(rng, _random_m(rng), n)
    first = _kkt_problem(rng, layout, P, A)
    truths: tuple[str | None, ...] = ()
    if kind == "nonconvex":
        P2 = P.copy()
        P2[0, :] = P2[:, 0] = 0.0
        P2[0, 0] = -0.53
        steps = [first, replace(first, P=P2), first]
    elif kind == "new rows":
        steps = [first, _kkt_problem(rng, layout, P, rows(rng, A.shape[0], n))]
    elif kind == "rescaled":
        steps = [first, _rescaled(rng, first, layout)]
    elif kind == "unbounded":
        ray = dual_infeasible(rng)
        steps = [_kkt_problem(rng, _layout_of(ray.problem), ray.problem.P, ray.problem.A),
                 ray.problem]
        truths = (None, ray.truth)
    elif kind == "infeasible":
        bad = primal_infeasible(rng)
        steps = [_kkt_problem(rng, _layout_of(bad.problem), bad.problem.P, bad.problem.A),
                 bad.problem]
        truths = (None, bad.truth)
    else:
        moved = _moved_bounds(rng, layout)
        steps = [first, _kkt_problem(rng, moved, P, A), first]
    return Reuse(tuple(steps), bool(rng.random() < 0.5), kind, truths)


def _kkt_problem(rng: np.random.Generator, layout: Layout, P: np.ndarray,
                 A: np.ndarray) -> Problem:
    """The problem with a fresh optimum (:func:`kkt_point`) for ``P``, ``A``, ``layout``."""
    x, z = kkt_point(rng, layout)
    q = -(P @ x + A.T @ rng.standard_normal(A.shape[0]) + z)
    return Problem.of(P, q, A, A @ x, layout.lb, layout.ub, layout.cones)


def _layout_of(problem: Problem) -> Layout:
    """The layout of a built problem (boxed entries read back from its bounds)."""
    members = set().union(*(range(c.start, c.start + c.dim) for c in problem.cones))
    box, free = {}, []
    for j in range(problem.n):
        low, high = np.isfinite(problem.lb[j]), np.isfinite(problem.ub[j])
        if low and high:
            box[j] = "fixed" if problem.lb[j] == problem.ub[j] else "both"
        elif low or high:
            box[j] = "lower" if low else "upper"
        elif j not in members:
            free.append(j)
    return Layout(problem.n, problem.cones, problem.lb, problem.ub, box, tuple(free))


def _rescaled(rng: np.random.Generator, problem: Problem, layout: Layout) -> Problem:
    """``problem`` with ``P`` and ``q`` or the rows (with ``b``) scaled by 1e-8 to 1e8."""
    factor = 10.0 ** (rng.choice([-1, 1]) * rng.uniform(4, 8))
    if rng.random() < 0.5:
        return replace(problem, P=problem.P * factor, q=problem.q * factor)
    scales = factor ** rng.uniform(0, 1, problem.A.shape[0])
    return replace(problem, A=problem.A * scales[:, None], b=problem.b * scales)


def _moved_bounds(rng: np.random.Generator, layout: Layout) -> Layout:
    """The layout with its boxed entries' sides drawn again (the structure changes)."""
    lb, ub, box = layout.lb.copy(), layout.ub.copy(), {}
    for j in layout.box:
        side = ("lower", "upper", "both", "fixed")[rng.integers(4)]
        low = rng.uniform(-2, 1)
        lb[j] = low if side in ("lower", "both", "fixed") else -np.inf
        ub[j] = low + rng.uniform(0.1, 3) if side in ("upper", "both") else (
            low if side == "fixed" else np.inf)
        box[j] = side
    return replace(layout, lb=lb, ub=ub, box=box)


def extreme_data(rng: np.random.Generator) -> Native:
    """Class 6: a problem of class 2, 3 or 4 transformed without changing its status:
    ``A`` and ``b`` scaled by 1e-300 to 1e-100 or 1e10 to 1e15 (all rows or each its
    own), ``P`` or ``q`` scaled by 1e-300 to 1e18, or the variables by 1e-8 to 1e8
    (uniformly within each cone block, bounds following); or, changing the problem
    (no known status then), friction coefficients of 1e-200 to 1e-6 or 1e6 to 1e200,
    which the documentation allows (finite and positive). Entries stay within the
    accepted 1e20. fccqp must keep its status's promises or raise an error naming the
    argument."""
    base = (feasible, primal_infeasible, dual_infeasible)[rng.integers(3)](rng)
    p, truth = base.problem, base.truth
    kind = str(rng.choice(["A tiny", "A huge", "rows", "P tiny", "P huge", "q tiny",
                           "q huge", "variables", "mu"]))
    if kind == "A tiny":
        factor = 10.0 ** -rng.uniform(100, 300)
        p = replace(p, A=p.A * factor, b=p.b * factor)
    elif kind == "A huge":
        factor = 10.0 ** rng.uniform(10, 15)
        p = replace(p, A=p.A * factor, b=p.b * factor)
    elif kind == "rows":
        scales = 10.0 ** rng.uniform(-150, 15, p.A.shape[0])
        p = replace(p, A=p.A * scales[:, None], b=p.b * scales)
    elif kind in ("P tiny", "P huge", "q tiny", "q huge"):
        low, high = (-300, -8) if kind.endswith("tiny") else (8, 18)
        data = getattr(p, kind[0])
        factor = min(10.0 ** rng.uniform(low, high), 1e19 / max(np.abs(data).max(), 1e-300))
        p = replace(p, **{kind[0]: data * factor})
    elif kind == "mu":
        cones = tuple(replace(c, mu=float(10.0 ** (rng.choice([-1, 1]) * rng.uniform(6, 200))))
                      if isinstance(c, FrictionCone) else c for c in p.cones)
        p, truth = replace(p, cones=cones), None
    else:
        s = 10.0 ** rng.uniform(-8, 8, p.n)
        for cone in p.cones:
            s[cone.start:cone.start + cone.dim] = s[cone.start]
        with np.errstate(invalid="ignore"):  # inf * ... of absent bounds stays inf
            p = replace(p, P=p.P * np.outer(s, s), q=p.q * s, A=p.A * s, lb=p.lb / s,
                        ub=p.ub / s)
    return Native(p, truth, f"{base.what}; {kind}", base.form, may_reject=True)


def degenerate(rng: np.random.Generator) -> Native:
    """Class 8: structures the other classes seldom draw, each with its status known by
    construction (:data:`_DEGENERATE`): an LP (``P = 0``) with a KKT point, a ray or no
    feasible point; one variable; no rows; every box entry fixed (sometimes every entry);
    rows repeated exactly or scaled, rows restating an entry, zero rows (``b`` consistent,
    or one copy off by a gap: infeasible); second-order cones of dimension 2 only, or of 6
    to 12; inactive bounds at 1e6 to 1e15; boxes 1e-9 to 1e-4 wide; 30 to 60 variables
    with up to 20 rows. A quarter of the time the absent bounds are passed as ``-1e30``
    and ``1e20``, which docs/api.md calls no bounds (the ``"sentinel"`` form)."""
    kind = _DEGENERATE[int(rng.integers(len(_DEGENERATE)))]
    problem, truth, what = kind(rng)
    form = "sentinel" if rng.random() < 0.25 else _form(rng)
    return Native(problem, truth, f"{kind.__name__[1:].replace('_', ' ')}: {what}", form)


def _lp(rng: np.random.Generator) -> tuple[Problem, str, str]:
    """``P = 0`` on a KKT point's problem, a ray's or an infeasible one (their status
    does not depend on ``P`` when ``P d = 0`` already holds along the ray)."""
    base = int(rng.integers(3))
    if base == 0:
        layout = random_layout(rng)
        A = rows(rng, _random_m(rng), layout.n)
        problem = _kkt_problem(rng, layout, np.zeros((layout.n, layout.n)), A)
        return problem, "solved", f"KKT point, n={layout.n} m={A.shape[0]}"
    made = (primal_infeasible, dual_infeasible)[base - 1](rng)
    p = made.problem
    return replace(p, P=np.zeros_like(p.P)), made.truth, made.what


def _one_variable(rng: np.random.Generator) -> tuple[Problem, str, str]:
    """``n = 1``: boxed or free, ``P`` zero or not, up to two (dependent) rows; free
    with ``P = 0``, no rows and ``q != 0`` it is unbounded."""
    layout = random_layout(rng, max_n=1, frictions=0, socs=0)
    P = psd(rng, 1)
    if layout.free and not P.any() and rng.random() < 0.3:
        q = np.array([rng.choice([-1.0, 1.0]) * _log_uniform(rng, 1e-3, 1e3)])
        empty = np.zeros((0, 1))
        return Problem.of(P, q, empty, np.zeros(0)), "dual_infeasible", "free, P = 0, q != 0"
    A = rows(rng, int(rng.integers(0, 3)), 1)
    problem = _kkt_problem(rng, layout, P, A)
    return problem, "solved", f"{next(iter(layout.box.values()), 'free')}, m={A.shape[0]}"


def _no_rows(rng: np.random.Generator) -> tuple[Problem, str, str]:
    """A KKT point's problem with ``m = 0``."""
    layout = random_layout(rng)
    problem = _kkt_problem(rng, layout, psd(rng, layout.n), np.zeros((0, layout.n)))
    return problem, "solved", f"KKT point, n={layout.n}"


def _all_fixed(rng: np.random.Generator) -> tuple[Problem, str, str]:
    """Every entry outside the cones fixed (``lb = ub``); half of the time no cones,
    so that the bounds alone decide ``x`` (rows consistent with it)."""
    none = rng.random() < 0.5
    layout = random_layout(rng, frictions=0 if none else None, socs=0 if none else None)
    lb, ub, box = layout.lb.copy(), layout.ub.copy(), {}
    for j in range(layout.n):
        if j not in layout.members:
            lb[j] = ub[j] = rng.uniform(-2, 2)
            box[j] = "fixed"
    layout = replace(layout, lb=lb, ub=ub, box=box, free=())
    A = rows(rng, _random_m(rng), layout.n)
    problem = _kkt_problem(rng, layout, psd(rng, layout.n), A)
    return problem, "solved", f"{len(box)} of {layout.n} entries fixed, m={A.shape[0]}"


def _repeated_rows(rng: np.random.Generator) -> tuple[Problem, str, str]:
    """Rows repeated exactly or scaled by -1 or 1e-3 to 1e3, rows ``e_j`` restating an
    entry (a cone's too) and zero rows, ``b`` consistent with a KKT point; a third of
    the time the ``b`` of a row that the others span is moved by 1e-6 to 1 times
    ``max(1, |b_i|)`` (infeasible)."""
    layout = random_layout(rng)
    n = layout.n
    A = rows(rng, int(rng.integers(1, MAX_M // 2 + 1)), n)
    extra = []
    for _ in range(int(rng.integers(1, 5))):
        pick = int(rng.integers(3))
        if pick == 0:
            scale = rng.choice([1.0, -1.0, _log_uniform(rng, 1e-3, 1e3)])
            extra.append(scale * A[int(rng.integers(A.shape[0]))])
        elif pick == 1:
            extra.append(np.eye(n)[int(rng.integers(n))])
        else:
            extra.append(np.zeros(n))
    copies = np.array(extra)
    A = np.vstack([A, copies])
    problem = _kkt_problem(rng, layout, psd(rng, n), A[rng.permutation(A.shape[0])])
    what = f"{copies.shape[0]} repeated, restating or zero rows, n={n} m={A.shape[0]}"
    dependent = [i for i in range(problem.A.shape[0]) if _dependent(problem.A, i)]
    if not dependent or rng.random() >= 1 / 3:
        return problem, "solved", what
    i = int(rng.choice(dependent))
    gap = _log_uniform(rng, 1e-6, 1.0)
    b = problem.b.copy()
    b[i] += gap * rng.choice([-1.0, 1.0]) * max(1.0, abs(b[i]))
    return replace(problem, b=b), "primal_infeasible", f"{what}, row {i} off by {gap:.2g}"


def _dependent(A: np.ndarray, i: int) -> bool:
    """Whether row ``i`` of ``A`` is a combination of the others (a zero row is)."""
    return np.linalg.matrix_rank(np.delete(A, i, axis=0)) == np.linalg.matrix_rank(A)


def _cone_sizes(rng: np.random.Generator) -> tuple[Problem, str, str]:
    """A KKT point's problem whose second-order cones all have dimension 2 (a wedge
    ``t >= |v|``), or 6 to 12."""
    dim = 2 if rng.random() < 0.5 else int(rng.integers(6, 13))
    layout = random_layout(rng, max_n=MAX_N if dim == 2 else 40,
                           socs=int(rng.integers(1, 4)), soc_dim=dim)
    A = rows(rng, _random_m(rng), layout.n)
    problem = _kkt_problem(rng, layout, psd(rng, layout.n), A)
    return problem, "solved", f"second-order cones of dimension {dim}, n={layout.n}"


def _far_bounds(rng: np.random.Generator) -> tuple[Problem, str, str]:
    """A KKT point's problem whose inactive sides are moved to 1e6 to 1e15 (a one-sided
    entry gets the other side there), beside the active ones."""
    layout = random_layout(rng, boxed=int(rng.integers(1, 9)))
    x, z = kkt_point(rng, layout)
    lb, ub = layout.lb.copy(), layout.ub.copy()
    for j in layout.box:
        if lb[j] == ub[j]:
            continue
        if z[j] >= 0 and x[j] > lb[j]:   # the lower side is inactive
            lb[j] = -_log_uniform(rng, 1e6, 1e15)
        if z[j] <= 0 and x[j] < ub[j]:
            ub[j] = _log_uniform(rng, 1e6, 1e15)
    P, A = psd(rng, layout.n), rows(rng, _random_m(rng), layout.n)
    q = -(P @ x + A.T @ rng.standard_normal(A.shape[0]) + z)
    problem = Problem.of(P, q, A, A @ x, lb, ub, layout.cones)
    return problem, "solved", f"KKT point, n={layout.n} m={A.shape[0]}"


def _thin_boxes(rng: np.random.Generator) -> tuple[Problem, str, str]:
    """A KKT point's problem whose two-sided boxes are 1e-9 to 1e-4 wide."""
    layout = random_layout(rng, boxed=int(rng.integers(1, 9)))
    ub = layout.ub.copy()
    for j, side in layout.box.items():
        if side == "both":
            ub[j] = layout.lb[j] + _log_uniform(rng, 1e-9, 1e-4)
    layout = replace(layout, ub=ub)
    A = rows(rng, _random_m(rng), layout.n)
    problem = _kkt_problem(rng, layout, psd(rng, layout.n), A)
    return problem, "solved", f"KKT point, n={layout.n} m={A.shape[0]}"


def _larger(rng: np.random.Generator) -> tuple[Problem, str, str]:
    """A KKT point's problem of 30 to 60 variables (up to 10 friction cones) and up to
    20 rows."""
    layout = random_layout(rng, min_n=30, max_n=60, frictions=int(rng.integers(0, 11)),
                           boxed=int(rng.integers(0, 25)))
    A = rows(rng, int(rng.integers(0, 21)), layout.n)
    problem = _kkt_problem(rng, layout, psd(rng, layout.n), A)
    return problem, "solved", f"KKT point, n={layout.n} m={A.shape[0]}"


_DEGENERATE = (_lp, _one_variable, _no_rows, _all_fixed, _repeated_rows, _cone_sizes,
               _far_bounds, _thin_boxes, _larger)
"""The structures of :func:`degenerate`, each ``rng -> (problem, truth, what)``."""


def qpsolvers_problem(rng: np.random.Generator) -> Qpsolvers:
    """Class 7a: a random problem in qpsolvers' form (``G x <= h`` with some rows
    active at the feasible point, equalities, a box), ``P`` positive definite or, when
    singular, every entry boxed, so that it is bounded; sometimes sparse."""
    import qpsolvers

    n = int(rng.integers(1, MAX_N + 1))
    x = rng.standard_normal(n)
    singular = rng.random() < 0.4
    P = psd(rng, n, rank=None if singular else n) + (0 if singular else 1e-3 * np.eye(n))
    q = rng.standard_normal(n) * 10.0 ** rng.uniform(-1, 1)
    G = rows(rng, int(rng.integers(0, MAX_M + 1)), n)
    h = G @ x + rng.uniform(0, 1, G.shape[0]) * (rng.random(G.shape[0]) < 0.6)
    A = rows(rng, int(rng.integers(0, min(MAX_M, n) + 1)), n)
    lb = x - rng.uniform(0, 2, n)
    ub = x + rng.uniform(0, 2, n)
    if not singular:
        lb[rng.random(n) < 0.5] = -np.inf
        ub[rng.random(n) < 0.5] = np.inf
    to = (lambda M: sp.csc_matrix(M)) if rng.random() < 0.3 else (lambda M: M)  # noqa: E731
    problem = qpsolvers.Problem(
        to(P), q, to(G) if G.size else None, h if G.size else None,
        to(A) if A.size else None, A @ x if A.size else None, lb, ub)
    return Qpsolvers(problem, f"n={n} G rows {G.shape[0]} A rows {A.shape[0]}"
                              f"{' singular P' if singular else ''}")


def cvxpy_problem(rng: np.random.Generator) -> Cvxpy:
    """Class 7b: a random feasible CVXPY problem: friction and second-order cones on
    variables (native), second-order cones on affine expressions (slacks), bounds,
    equalities, inequalities, ``P`` PSD of any rank (Clarabel says whether it is
    bounded)."""
    layout = random_layout(rng)
    n = layout.n
    x = interior_point(rng, layout)
    rank = n if rng.random() < 0.5 else int(rng.integers(0, n + 1))
    M = rng.standard_normal((n, rank)) * 10.0 ** rng.uniform(-1, 1)
    cones = []
    for cone in layout.cones:
        axis, mu = layout.axis(cone)
        if isinstance(cone, FrictionCone):
            if cone.normal is not None:  # only axis-aligned friction cones map natively
                continue
            cones.append((cone.start + 2, (cone.start, cone.start + 1), mu))
        else:
            cones.append((cone.start, tuple(range(cone.start + 1, cone.start + cone.dim)), 1.0))
    affine = []
    for _ in range(int(rng.integers(0, 2))):
        k = int(rng.integers(1, 4))
        B, c = rng.standard_normal((k, n)), rng.standard_normal(n)
        v0 = rng.standard_normal(k)
        t0 = np.linalg.norm(B @ x + v0) - c @ x + rng.uniform(0, 1)
        affine.append((c, float(t0), B, v0))
    G = rows(rng, int(rng.integers(0, 5)), n)
    A = rows(rng, int(rng.integers(0, 5)), n)
    return Cvxpy(M, rng.standard_normal(n), A, A @ x, G,
                 G @ x + rng.uniform(0, 1, G.shape[0]) * (rng.random(G.shape[0]) < 0.6),
                 layout.lb, layout.ub, tuple(cones), tuple(affine),
                 f"n={n} rank {rank}, {len(cones)} native and {len(affine)} affine cones")


CLASSES: dict[str, Callable[[np.random.Generator], object]] = {
    "bad_input": bad_input,
    "feasible": feasible,
    "primal_infeasible": primal_infeasible,
    "dual_infeasible": dual_infeasible,
    "solver_reuse": solver_reuse,
    "extreme_data": extreme_data,
    "qpsolvers": qpsolvers_problem,
    "cvxpy": cvxpy_problem,
    "degenerate": degenerate,
}
"""The fuzzer's classes by name: issue 26's failure classes in its order, then the
structures of :func:`degenerate`."""
CAMPAIGN_CLASSES = tuple(CLASSES)[:8]
"""The classes a campaign runs unless told otherwise: issue 26's, so that a campaign's
seed names the same cases as before :func:`degenerate` existed (notes/verdicts.md)."""


@dataclass(frozen=True)
class Case:
    """One fuzz case: a class name, a seed and the class's generator; the scenario is
    ``builder(np.random.default_rng(seed))``, the same on every run."""

    name: str
    seed: int
    builder: Callable[[np.random.Generator], object]

    @classmethod
    def of(cls, name: str, seed: int) -> Case:
        """The case of class ``name`` (a key of :data:`CLASSES`) and ``seed``."""
        return cls(name, seed, CLASSES[name])

    @classmethod
    def parse(cls, text: str) -> Case:
        """The case written ``"class:seed"`` (as ``str(case)`` writes it)."""
        name, seed = text.rsplit(":", 1)
        return cls.of(name, int(seed))

    def scenario(self) -> object:
        """The scenario this case stands for."""
        return self.builder(np.random.default_rng(self.seed))

    def __str__(self) -> str:
        return f"{self.name}:{self.seed}"


# ----------------------------------------------------------------------------- judging


@dataclass(frozen=True)
class Verdict:
    """What :func:`judge_case` found: ``failure`` (``None`` or ``"kind: description"``),
    ``outcome`` (fccqp's status name, or the exception it raised), ``reference``
    (Clarabel's conclusive status where it agrees with the construction, else None)
    and ``conflict`` (Clarabel's conclusive status differs from the construction's)."""

    failure: str | None
    outcome: str
    reference: str | None = None
    conflict: bool = False

    @property
    def kind(self) -> str | None:
        """The failure's kind, the word before the first colon."""
        return None if self.failure is None else self.failure.split(":", 1)[0]


def judge(case: Case, backend: str = "auto") -> str | None:
    """``None`` when fccqp answered ``case`` honestly on ``backend`` (one of
    ``fccqp.settings.KKT_BACKENDS``), else the failure's description."""
    return judge_case(case, backend).failure


def judge_case(case: Case, backend: str = "auto") -> Verdict:
    """The :class:`Verdict` on ``case`` solved with ``kkt_backend=backend``."""
    if backend not in KKT_BACKENDS:
        raise ValueError(f"backend must be one of {KKT_BACKENDS}, got {backend!r}")
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore")  # qpsolvers' and CVXPY's advice, overflow in data
        scenario = case.scenario()
        if isinstance(scenario, BadInput):
            return _judge_bad_input(scenario, backend)
        if isinstance(scenario, Native):
            return _judge_native(scenario, backend)
        if isinstance(scenario, Reuse):
            return _judge_reuse(scenario, backend)
        if isinstance(scenario, Qpsolvers):
            return _judge_qpsolvers(scenario, backend)
        return _judge_cvxpy(scenario, backend)


def _names(message: str, names: tuple[str, ...]) -> bool:
    """Whether ``message`` names one of ``names`` as a word (``cones`` in ``cones[1].mu``)."""
    return any(re.search(rf"(?<![\w.]){re.escape(name)}(?!\w)", message) for name in names)


_ARGUMENT_NAMES = ("P", "q", "A", "b", "lb", "ub", "cones", "x0", "settings")


def _error(exn: BaseException) -> str:
    return f"{type(exn).__name__}: {str(exn)[:300]}"


def _judge_bad_input(s: BadInput, backend: str) -> Verdict:
    overrides = {"kkt_backend": backend, **s.overrides}
    try:
        if s.x0 is not None:
            result = fccqp.Solver(**overrides).solve(*s.args, x0=s.x0)
        else:
            result = fccqp.solve(*s.args, settings=s.settings, **overrides)
    except (ValueError, TypeError) as exn:
        if _names(str(exn), s.names):
            return Verdict(None, type(exn).__name__)
        return Verdict(f"exception: {s.what}: the error names none of {s.names}: "
                       f"{_error(exn)}", type(exn).__name__)
    except Exception as exn:  # noqa: BLE001 - any other exception is the failure
        return Verdict(f"exception: {s.what}: {_error(exn)}", type(exn).__name__)
    return Verdict(f"accepted: {s.what}: no error, status {result.status.name}",
                   result.status.name)


def _clarabel(problem: Problem, truth: str | None) -> tuple[str | None, bool]:
    """Clarabel's conclusive status if it agrees with ``truth``, and whether the two
    conflict. Clarabel needs a PSD ``P``: otherwise no reference. Without a ``truth``
    (a problem the construction does not decide) Clarabel's status is the reference
    only when its answer, a point or a certificate, passes :func:`verify.check_solution`
    on ``problem``: at friction coefficients of 1e-83 Clarabel's form (a row ``mu n'``)
    loses ``n'f >= 0``, and it called a bounded problem unbounded along a ray with
    ``n'f = -1`` (extreme_data:500099); on a ray it called "solved" a point of size
    2.6e14 along it (solver_reuse:700137). An unproven answer counts as a conflict."""
    if np.linalg.eigvalsh(problem.P)[0] < -1e-9 * max(1e-300, np.abs(problem.P).max()):
        return None, False
    try:
        reference = clarabel_solve(*problem.args())
    except Exception:  # noqa: BLE001 - Clarabel refusing extreme data is no verdict
        return None, False
    status = reference.status
    if status not in ANSWERS:
        return None, False
    if truth is not None and status != truth:
        return None, True
    if truth is None and not _proven(problem, reference):
        return None, True
    if status == "solved" and _below_rounding(problem, reference):
        return None, False
    return status, False


def _below_rounding(problem: Problem, reference) -> bool:
    """Whether Clarabel's optimum fails :mod:`verify` on a problem whose dual test asks
    less than the rounding of ``P x`` at that point (``eps |P||x|``, the backward error
    of the product, which no double-precision point can be judged below): then no
    ``SOLVED`` can be verified but by chance, and an honest non-claim (a stall) is no
    failure, while any claim is still verified. ``P`` of 7e13 about a point of size 2
    in its near-null space: ``|P||x|`` of 1.4e14 puts the rounding of the stationarity
    at 3e-2 against a test of 2e-4, and Clarabel's point misses it by 5e-3
    (extreme_data:1900050). The scale is the data's and the primal point's, never the
    multipliers', as in :mod:`verify`."""
    x = reference.x
    if x is None or not np.all(np.isfinite(x)):
        return False
    P = problem.P
    rounding = np.finfo(np.float64).eps * float(np.max(np.abs(P) @ np.abs(x), initial=0.0))
    scale = max(1.0, float(np.max(np.abs(problem.q), initial=0.0)),
                float(np.max(np.abs(P @ x), initial=0.0)))
    return rounding > Tolerances.of().bound(scale) and not _proven(problem, reference)


def _proven(problem: Problem, reference) -> bool:
    """Whether Clarabel's answer (its point and multipliers, or its certificate) passes
    :mod:`verify`'s checks for its status (no claimed residuals to compare)."""
    status = {"solved": Status.SOLVED, "primal_infeasible": Status.PRIMAL_INFEASIBLE,
              "dual_infeasible": Status.DUAL_INFEASIBLE}[reference.status]
    empty = np.zeros(0)
    claim = fccqp.Result(x=empty if reference.x is None else reference.x,
                         y=empty if reference.y is None else reference.y,
                         z=empty if reference.z is None else reference.z,
                         status=status, obj=np.nan, iterations=0, prim_res=np.inf,
                         dual_res=np.inf, setup_time=0.0, solve_time=0.0, rho=np.nan,
                         factorizations=0, certificate=reference.certificate, gap=np.nan)
    return check_solution(problem, claim, Tolerances.of()).passed


def _arguments(problem: Problem, form: str) -> tuple:
    """``problem``'s arguments for ``fccqp.solve`` in the given form (see :class:`Native`)."""
    P, q, A, b, lb, ub, cones = problem.args()
    if form == "sparse":
        P, A = sp.csc_matrix(P), sp.csc_matrix(A)
    elif form == "views":
        P, A = np.asfortranarray(P), np.asfortranarray(A)
        q, b, lb, ub = (np.repeat(v, 2)[::2] for v in (q, b, lb, ub))
    elif form == "sentinel":
        lb, ub = np.where(np.isfinite(lb), lb, -1e30), np.where(np.isfinite(ub), ub, 1e20)
    elif form == "none":
        if A.shape[0] == 0:
            A = b = None
        if not np.isfinite(lb).any():
            lb = None
        if not np.isfinite(ub).any():
            ub = None
    return P, q, A, b, lb, ub, cones


def _judge_result(problem: Problem, result: fccqp.Result, settings: fccqp.Settings,
                  reference: str | None) -> str | None:
    """The failure of ``result`` on ``problem``, or None: a status that contradicts the
    reference, a check of :func:`verify.check_solution` that fails, a stall where the
    reference has an answer (in that order of precedence for the kind)."""
    status = result.status
    found = []
    if reference in ("primal_infeasible", "dual_infeasible") and status is Status.SOLVED:
        found.append(("status", f"{status.name} where Clarabel says {reference}"))
    if reference == "solved" and status.is_infeasible():
        found.append(("status", f"{status.name} where Clarabel finds an optimum"))
    report = check_solution(problem, result, Tolerances.of(settings))
    if not report.passed:
        checks = "; ".join(f"{name} {value:.3g} > {bound:.3g}"
                           for name, (value, bound) in report.failures.items())
        found.append(("verify", f"{status.name} fails {checks}"))
    if reference is not None and status in STALLED:
        found.append(("stalled", f"{status.name} where Clarabel says {reference}"))
    if not found:
        return None
    return (f"{found[0][0]}: " + "; ".join(text for _, text in found)
            + f" ({result.iterations} iterations, backend {result.backend})")


def _judge_native(s: Native, backend: str) -> Verdict:
    settings = fccqp.Settings(kkt_backend=backend)
    reference, conflict = _clarabel(s.problem, s.truth)
    try:
        result = fccqp.solve(*_arguments(s.problem, s.form), settings=settings)
    except (ValueError, TypeError) as exn:
        honest = s.may_reject and _names(str(exn), _ARGUMENT_NAMES) and \
            "not convex" not in str(exn)
        failure = None if honest else f"rejected: {s.what}: {_error(exn)}"
        return Verdict(failure, type(exn).__name__, reference, conflict)
    except Exception as exn:  # noqa: BLE001 - any other exception is the failure
        return Verdict(f"exception: {s.what}: {_error(exn)}", type(exn).__name__,
                       reference, conflict)
    failure = _judge_result(s.problem, result, settings, reference)
    if failure is not None:
        kind, text = failure.split(": ", 1)
        failure = f"{kind}: {s.what}: {text}"
    return Verdict(failure, result.status.name, reference, conflict)


def _judge_reuse(s: Reuse, backend: str) -> Verdict:
    settings = fccqp.Settings(kkt_backend=backend)
    solver = fccqp.Solver(settings)
    first = s.steps[0]
    arrays = [np.array(v) for v in first.args()[:6]]   # refilled in place
    outcome, reference, conflict = "", None, False
    for k, step in enumerate(s.steps):
        if s.in_place:
            for array, value in zip(arrays, step.args()[:6], strict=True):
                np.copyto(array, value)
            args = (*arrays, first.cones if step.cones == first.cones else step.cones)
        else:
            args = tuple(np.array(v) for v in step.args()[:6]) + (step.cones,)
        try:
            fresh, alone = None, fccqp.solve(*step.args(), settings=settings).status.name
        except (ValueError, TypeError) as exn:
            fresh, alone = exn, type(exn).__name__
        where = (f"step {k + 1} of {len(s.steps)} ({s.what}, in place {s.in_place}, "
                 f"fresh solve {alone})")
        try:
            result = solver.solve(*args)
        except (ValueError, TypeError) as exn:
            outcome = type(exn).__name__
            if fresh is None:
                return Verdict(f"reuse: {where}: {_error(exn)} where a fresh solve "
                               "returns", outcome, reference, conflict)
            if not _names(str(exn), _ARGUMENT_NAMES):
                return Verdict(f"exception: {where}: the error names no argument: "
                               f"{_error(exn)}", outcome, reference, conflict)
            continue
        except Exception as exn:  # noqa: BLE001 - any other exception is the failure
            return Verdict(f"exception: {where}: {_error(exn)}", type(exn).__name__,
                           reference, conflict)
        outcome = result.status.name
        if fresh is not None:
            return Verdict(f"reuse: {where}: {outcome} where a fresh solve raises "
                           f"{_error(fresh)}", outcome, reference, conflict)
        reference, conflict = _clarabel(step, s.truths[k] if s.truths else None)
        failure = _judge_result(step, result, settings, reference)
        if failure is not None:
            kind, text = failure.split(": ", 1)
            return Verdict(f"{kind}: {where}: {text}", outcome, reference, conflict)
    return Verdict(None, outcome, reference, conflict)


def _judge_qpsolvers(s: Qpsolvers, backend: str) -> Verdict:
    import qpsolvers

    settings = fccqp.Settings(kkt_backend=backend)
    reference = None
    clarabel = qpsolvers.solve_problem(s.problem, solver="clarabel", tol_gap_abs=1e-10,
                                       tol_gap_rel=1e-10, tol_feas=1e-10)
    if clarabel.found:
        reference = "solved"
    try:
        solution = qpsolvers.solve_problem(s.problem, solver="fccqp", kkt_backend=backend)
    except Exception as exn:  # noqa: BLE001 - any exception on valid data is the failure
        return Verdict(f"exception: {s.what}: {_error(exn)}", type(exn).__name__, reference)
    problem, result = from_qpsolvers(s.problem, solution)
    failure = _judge_result(problem, result, settings, reference)
    if failure is not None:
        kind, text = failure.split(": ", 1)
        failure = f"{kind}: {s.what}: {text}"
    return Verdict(failure, result.status.name, reference, not clarabel.found)


_CVXPY_STATUS = {"optimal": "solved", "optimal_inaccurate": "solved",
                 "infeasible": "primal_infeasible", "infeasible_inaccurate": "primal_infeasible",
                 "unbounded": "dual_infeasible", "unbounded_inaccurate": "dual_infeasible"}


def _build_cvxpy(s: Cvxpy):
    """The CVXPY problem of ``s`` (a new object each time: CVXPY caches per problem)."""
    import cvxpy as cp

    x = cp.Variable(s.q.shape[0])
    objective = 0.5 * cp.sum_squares(s.M.T @ x) + s.q @ x
    constraints = []
    if s.A.shape[0]:
        constraints.append(s.A @ x == s.b)
    if s.G.shape[0]:
        constraints.append(s.G @ x <= s.h)
    for j in np.flatnonzero(np.isfinite(s.lb)):
        constraints.append(x[j] >= s.lb[j])
    for j in np.flatnonzero(np.isfinite(s.ub)):
        constraints.append(x[j] <= s.ub[j])
    for t, v, scale in s.cones:
        constraints.append(cp.SOC(scale * x[t], x[list(v)]))
    for c, t0, B, v0 in s.affine_cones:
        constraints.append(cp.SOC(c @ x + t0, B @ x + v0))
    return cp.Problem(cp.Minimize(objective), constraints)


def _judge_cvxpy(s: Cvxpy, backend: str) -> Verdict:
    import cvxpy as cp

    from fccqp_cvxpy import FCCQP

    clarabel = _build_cvxpy(s)
    try:
        clarabel.solve(solver="CLARABEL", tol_gap_abs=1e-10, tol_gap_rel=1e-10,
                       tol_feas=1e-10)
        reference = _CVXPY_STATUS.get(clarabel.status)
    except cp.error.SolverError:
        reference = None
    problem = _build_cvxpy(s)
    try:
        problem.solve(solver=FCCQP, kkt_backend=backend)
    except cp.error.SolverError as exn:
        failure = None if reference is None else (
            f"stalled: {s.what}: SolverError (documented for NUMERICAL_ERROR) where "
            f"Clarabel says {reference}: {exn}")
        return Verdict(failure, "SolverError", reference)
    except Exception as exn:  # noqa: BLE001 - any exception on valid data is the failure
        return Verdict(f"exception: {s.what}: {_error(exn)}", type(exn).__name__, reference)
    stats = problem.solver_stats.extra_stats
    t, result = stats["translation"], stats["result"]
    translated = Problem.of(t.P, t.q, t.A, t.b, t.lb, t.ub, t.cones)
    failure = _judge_result(translated, result, fccqp.Settings(kkt_backend=backend),
                            reference)
    if failure is not None:
        kind, text = failure.split(": ", 1)
        failure = f"{kind}: {s.what}: {text}"
    return Verdict(failure, result.status.name, reference)
