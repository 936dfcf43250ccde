"""Solver settings and presets."""

from __future__ import annotations

import dataclasses
import math
import numbers
from dataclasses import dataclass

import numpy as np

INT_MAX = 2**31 - 1
"""Largest iteration count or interval: what a compiled 32-bit counter holds."""
MAX_SCALING = 100
"""Most Ruiz passes: equilibration settles within 10-25, more only costs setup time."""
MAX_ANDERSON_MEMORY = 100
"""Most Anderson memory: each step solves a least-squares problem of this size."""
MAX_POLISH_REFINE_ITER = 100
"""Most re-linearizations of polishing: Newton's method on the cones' tangent planes
converges in 1-3 when the active set is right."""

MAX_DENSE_KKT_ROWS = 5000
"""Largest KKT matrix (``n + m`` rows) that the dense core factors. At this size the
dense matrix takes 200 MB and one factorization about 4e10 flops (seconds), ten times
the 500 rows the dense core is meant for; a larger problem takes the sparse path
(``kkt_backend="sparse"``: ``P`` and ``A`` in compressed columns, factored by qdldl),
whatever ``kkt_backend`` says."""
KKT_BACKENDS = ("auto", "schur_reduced", "ldl_reduced", "ldl_full", "sparse")
"""The values of ``Settings.kkt_backend``."""

REALTIME_BUDGET = 2e-3
"""Default budget of :meth:`Settings.realtime` in seconds. Measured on the full benchmark
at 9f0fb22 (budgets 0.5, 1, 2, 3 ms; share solved on solo12 / anymal_c / go2 /
talos_reduced): 100 / 100 / 100 / 58.5 %, 100 / 100 / 100 / 89.8 %, 100 / 100 / 100 /
99.0 %, 100 / 100 / 100 / 99.8 % (at f956755, on a slower machine state: talos 42.5,
68.2, 97.3, 98.8 %; at 2a7b277 58.5, 84.0, 96.2, 99.8 %, the quadrupeds 99.5-100 % at
0.5 ms and 100 % from 1 ms; at c6b0d4d, on a faster Intel machine, talos 83.2, 96.5,
99.8, 100 % and the quadrupeds 100 % at every budget; at c02d1c8, on the AMD machine
again, talos 92.0, 98.0, 100, 100 %, the quadrupeds 100 % at every budget). The
quadrupeds need 0.5 to 1 ms (their median solve is 42-106 us, and the budget rarely
binds); the humanoid's ticks whose active set changed need more than 1 ms. 2 ms is the
end of a control tick's usual range; 3 ms (pass ``budget=3e-3``) serves the humanoid
best."""
REALTIME_MIN_ITER = 15
"""Iterations :meth:`Settings.realtime` runs whatever the budget: the paper's real-time
count, so that each tick of a loop whose budget its setup spends still progresses."""

_REAL_RANGES = {
    # name: (low, high, low excluded, high excluded)
    "rho": (0.0, math.inf, True, True),
    "sigma": (0.0, math.inf, True, True),
    "alpha": (0.0, 2.0, True, True),
    "eps_abs": (0.0, math.inf, False, True),
    "eps_rel": (0.0, math.inf, False, True),
    "eps_prim_inf": (0.0, math.inf, True, True),
    "eps_dual_inf": (0.0, math.inf, True, True),
    "time_limit": (0.0, math.inf, True, False),
    "adaptive_rho_tolerance": (1.0, math.inf, True, True),
}
"""Real settings and their allowed interval; ``inf`` is allowed only for ``time_limit``."""
_INTEGER_RANGES = {
    "max_iter": (1, INT_MAX),
    "min_iter": (0, INT_MAX),
    "check_termination": (1, INT_MAX),
    "adaptive_rho_interval": (1, INT_MAX),
    "anderson_memory": (0, MAX_ANDERSON_MEMORY),
    "scaling": (0, MAX_SCALING),
    "polish_refine_iter": (0, MAX_POLISH_REFINE_ITER),
}
"""Integer settings and their allowed closed interval."""
_BOOLEANS = ("adaptive_rho", "restore_feasibility", "polish", "warm_start", "verbose")


def _real(name: str, value: object, low: float, high: float, low_open: bool,
          high_open: bool) -> float:
    """``value`` as a float in the interval, or an error naming the setting."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise TypeError(f"setting {name} must be a real number, got {value!r}")
    value = float(value)
    below = value <= low if low_open else value < low
    above = value >= high if high_open else value > high
    if math.isnan(value) or below or above:
        interval = f"{'(' if low_open else '['}{low:g}, {high:g}{')' if high_open else ']'}"
        raise ValueError(f"setting {name} must lie in {interval}, got {value}")
    return value


def _integer(name: str, value: object, low: int, high: int) -> int:
    """``value`` as an int in ``[low, high]``, or an error naming the setting."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
        raise TypeError(f"setting {name} must be an integer, got {value!r}")
    value = int(value)
    if not low <= value <= high:
        raise ValueError(f"setting {name} must lie in [{low}, {high}], got {value}")
    return value


@dataclass(frozen=True)
class Settings:
    """Settings of the ADMM solver; every field has a default.

    Names follow OSQP where the meaning is the same. Tolerances apply to the
    unscaled problem, in the infinity norm. Construction checks every field: a value
    of the wrong type (``None``, a string, a complex number, a bool for a number)
    raises ``TypeError`` and one outside its range ``ValueError``, both naming the
    setting. Reals must be finite (``time_limit`` may be ``inf``); integers are
    bounded by :data:`INT_MAX`, :data:`MAX_SCALING`, :data:`MAX_ANDERSON_MEMORY` and
    :data:`MAX_POLISH_REFINE_ITER`.
    """

    rho: float = 0.1
    """Initial ADMM penalty on the box and cone constraints (scaled problem) of a cold
    start; a warm start, and under a time limit a cold start after an earlier solve of
    the workspace, begins at the rho the last solve adapted (docs/algorithm.md)."""
    sigma: float = 1e-6
    """Proximal regularization of the x-update's full form (unused by the reduced form)."""
    alpha: float = 1.6
    """Over-relaxation parameter, in (0, 2)."""
    eps_abs: float = 1e-5
    """Absolute tolerance on primal and dual residuals."""
    eps_rel: float = 1e-5
    """Relative tolerance on primal and dual residuals."""
    eps_prim_inf: float = 1e-6
    """Tolerance of the primal infeasibility certificate: the residual of ``A'dy + dz ~ 0``
    relative to its terms (the separation ``b'dy + sigma_C(dz) < 0`` must dominate it)."""
    eps_dual_inf: float = 1e-6
    """Tolerance of the dual infeasibility certificate."""
    max_iter: int = 4000
    """Iteration budget, at most :data:`INT_MAX`; when it runs out the current iterate
    is returned. Under a finite ``time_limit`` the clock is the budget: a run at its cap
    whose distance to tolerance (the largest residual over its tolerance) halved over
    the last ``max_iter / 2`` iterations gets ``max_iter / 2`` more, again and again
    while it keeps halving (``fccqp.tuning.CONVERGING``) or, with
    ``fccqp.tuning.AUXILIARY_TIME`` left, while its lowest distance falls at a geometric
    rate that reaches the tolerance within the time left; each time after trying the
    polish that ends an untimed run at its cap (kept when it solves). A stalled run
    still stops at the cap, and with ``AUXILIARY_TIME`` left gets the certificates and
    retries of an untimed one within that time."""
    time_limit: float = math.inf
    """Wall-clock budget of one solve in seconds (setup included); ``inf`` for none."""
    min_iter: int = 0
    """Iterations that run even when ``time_limit`` is spent (never more than
    ``max_iter``): in a control loop every tick must make progress, or a warm start that
    the budget stops at its setup never converges (talos_reduced at a 1 ms budget:
    15 % solved without, see :meth:`realtime`)."""
    check_termination: int = 1
    """Check residuals every this many iterations (in the reduced form an ``O(s^2)``
    estimate first decides whether the full check is worth running)."""
    adaptive_rho: bool = True
    """Rescale rho to balance primal and dual residuals, refactoring when it changes."""
    adaptive_rho_interval: int = 10
    """Iterations between two rho updates, and between two unconditional residual checks."""
    adaptive_rho_tolerance: float = 5.0
    """Refactor only when rho would change by more than this factor, or by more than its
    square root at ``fccqp.tuning.RHO_PERSISTENCE`` updates in a row while the residuals
    stall (a move then undone if they fall more slowly after it)."""
    anderson_memory: int = 10
    """Anderson acceleration memory (0 disables, at most :data:`MAX_ANDERSON_MEMORY`);
    safeguarded, see :mod:`fccqp.anderson`."""
    scaling: int = 4
    """Ruiz equilibration passes (0 disables scaling, at most :data:`MAX_SCALING`). Four
    rather than OSQP's 10: on the general-QP suite at eps 1e-6 (``python -m
    benchmarks.general_suite``) both solve 543 of 543 problems (542 with 10 before
    Anderson's weight cap), on the WBC sets at default settings both solved and polished
    100 % with the same worst gap and torque error (talos: 66 against 55 mean
    iterations, go2: 12 against 29), and each pass costs 50k instructions on go2, 270k
    on talos (6-20 % of a warm tick)."""
    restore_feasibility: bool = True
    """Return a point in the box and the cones: the violating entries are pinned at
    their projection and the others respond through the KKT system, keeping
    ``A x = b``; see :mod:`fccqp.restoration`. The dense path only: it has no effect on
    the sparse path (``kkt_backend="sparse"``), which has no table of KKT columns."""
    polish: bool = True
    """After ADMM (solved or stopped by a budget), solve the equality-constrained QP on
    the active set its iterate suggests (box entries at a bound, cone blocks at the apex
    or on a tangent plane) and return that point when it passes a KKT check on the
    user's problem; ``Result.polished`` says whether it did. See :mod:`fccqp.polish`.
    On by default: on the WBC sets (go2, talos_reduced; 200 warm QPs each) it polished
    99 % of the solves, cut the p95 torque error against the Clarabel reference from 15
    and 31 Nm to 0.009 and 0.008 Nm and the worst relative objective gap from 4e-5 and
    1.1e-3 to 9e-9 and 4e-7 (docs/performance.md has its current cost). A warm start
    from a polished solution polishes its active set first, before any iteration, and
    without a time limit a run polishes early once the active set its iterate points
    to has settled (``fccqp.tuning.EARLY_POLISH_GATE``); under a time limit, once it
    has held as long as it took to form (``fccqp.tuning.SETTLE_ITERATIONS``)."""
    polish_refine_iter: int = 20
    """Most re-linearizations of the boundary cones' tangent planes in polishing (Newton
    steps, taken only until the cone function is met to 1e-13 or stops improving; a
    step reuses the last factorization while the steps converge fast; at most
    :data:`MAX_POLISH_REFINE_ITER`). From ADMM's point Newton sometimes needs about 8
    on whole-body control (small contact forces); on go2 10 instead of 3 raised the
    polished share from 91 % to 92 % for 0.2 more factorizations per solve. From a
    guess whose first solve slid far along a new block's plane (the cost flat on the
    forces) it needed up to 19, and with 10 solo12's realtime warm ticks missed 2 polishes
    in 400 (notes/polish.md, "polishmiss"); talos' polishes never needed more than 10."""
    kkt_backend: str = "auto"
    """Linear-system backend of the x-update: ``"schur_reduced"`` (Cholesky of ``P + R``
    and of ``A (P + R)^-1 A'``, reduced iteration), ``"ldl_reduced"`` (LDL', reduced
    iteration), ``"ldl_full"`` (LDL', one KKT solve per iteration), ``"sparse"`` (the
    sparse path: ``scipy.sparse`` data and a sparse LDL' from ``qdldl``, one KKT solve
    per iteration, :mod:`fccqp.kkt_sparse`) or ``"auto"`` (the first of the dense ones
    that applies and pays; see docs/algorithm.md). A forced dense backend that cannot
    factor the matrix falls back to the next one in that order, and a reduced one takes
    ``"ldl_full"`` when the cold start cannot meet ``A x = b`` (numerically dependent or
    inconsistent rows, on which the reduced form's ``A (P + R)^-1 A'`` is nearly
    singular and its final ``A x = b`` correction moves ``x``); a problem whose KKT
    matrix has more than :data:`MAX_DENSE_KKT_ROWS` rows takes the sparse path whatever
    this says. ``Result.backend`` says which ran."""
    warm_start: bool = True
    """Start from the previous solution (used by :class:`fccqp.Solver`)."""
    verbose: bool = False
    """Print one line per residual check."""

    def __post_init__(self) -> None:
        """Check every field's type and range, naming the field; store plain ``float``
        / ``int`` / ``bool`` values so that equal settings hash equal."""
        for name, (low, high, low_open, high_open) in _REAL_RANGES.items():
            object.__setattr__(self, name, _real(name, getattr(self, name), low, high,
                                                 low_open, high_open))
        for name, (low, high) in _INTEGER_RANGES.items():
            object.__setattr__(self, name, _integer(name, getattr(self, name), low, high))
        for name in _BOOLEANS:
            value = getattr(self, name)
            if not isinstance(value, (bool, np.bool_)):
                raise TypeError(f"setting {name} must be a bool, got {value!r}")
            object.__setattr__(self, name, bool(value))
        if self.eps_abs == 0 and self.eps_rel == 0:
            raise ValueError("settings eps_abs and eps_rel cannot both be 0")
        if self.kkt_backend not in KKT_BACKENDS:
            raise ValueError(
                f"setting kkt_backend must be one of {', '.join(KKT_BACKENDS)}, "
                f"got {self.kkt_backend!r}"
            )

    def replace(self, **overrides: object) -> Settings:
        """Return a copy with some fields changed; unknown names raise ``ValueError``."""
        unknown = sorted(set(overrides) - {f.name for f in dataclasses.fields(self)})
        if unknown:
            valid = ", ".join(f.name for f in dataclasses.fields(self))
            raise ValueError(f"unknown setting(s) {', '.join(unknown)}; valid settings: {valid}")
        return dataclasses.replace(self, **overrides)

    @classmethod
    def realtime(cls, budget: float = REALTIME_BUDGET, **overrides: object) -> Settings:
        """Preset for control loops: a time budget per solve, warm start, polishing.

        A controller has a deadline, not an iteration count: each solve returns within
        ``budget`` seconds (setup included; see :attr:`time_limit`) the best point it
        found, with ``A x = b`` exact. A warm start from a polished solution first
        polishes the previous active set (no iteration; on whole-body control not even
        ADMM's factorization): in a control loop that is the answer most ticks.
        Otherwise ADMM runs, polishing when it meets the tolerance, and stops early
        enough to polish or restore within the budget, but not before
        :data:`REALTIME_MIN_ITER` iterations (a budget shorter than the setup plus those
        is overrun rather than wasted: the next tick starts from there).
        Tolerances 1e-4 (the paper's). The default budget, :data:`REALTIME_BUDGET`, is
        2 ms; the figures per robot and budget are in docs/performance.md.
        """
        budget = _real("budget", budget, 0.0, math.inf, True, False)
        preset = cls(
            time_limit=budget, min_iter=REALTIME_MIN_ITER, eps_abs=1e-4, eps_rel=1e-4,
            warm_start=True, polish=True,
        )
        return preset.replace(**overrides)
