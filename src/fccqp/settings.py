"""Solver settings and presets."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass


@dataclass(frozen=True)
class Settings:
    """Settings of the ADMM solver; every field has a default.

    Names follow OSQP where the meaning is the same. Tolerances apply to the
    unscaled problem, in the infinity norm.
    """

    rho: float = 0.1
    """Initial ADMM penalty on the box and cone constraints (scaled problem)."""
    sigma: float = 1e-6
    """Proximal regularization of the x-update's full form (unused by the reduced form)."""
    alpha: float = 1.6
    """Over-relaxation parameter, in (0, 2)."""
    eps_abs: float = 1e-5
    """Absolute tolerance on primal and dual residuals."""
    eps_rel: float = 1e-5
    """Relative tolerance on primal and dual residuals."""
    eps_prim_inf: float = 1e-6
    """Tolerance of the primal infeasibility certificate."""
    eps_dual_inf: float = 1e-6
    """Tolerance of the dual infeasibility certificate."""
    max_iter: int = 4000
    """Iteration budget; when it runs out the current iterate is returned."""
    time_limit: float = math.inf
    """Wall-clock budget of one solve in seconds (setup included); ``inf`` for none."""
    check_termination: int = 1
    """Check residuals every this many iterations (in the reduced form an ``O(s^2)``
    estimate first decides whether the full check is worth running)."""
    adaptive_rho: bool = True
    """Rescale rho to balance primal and dual residuals, refactoring when it changes."""
    adaptive_rho_interval: int = 10
    """Iterations between two rho updates, and between two unconditional residual checks."""
    adaptive_rho_tolerance: float = 5.0
    """Refactor only when rho would change by more than this factor."""
    anderson_memory: int = 10
    """Anderson acceleration memory (0 disables); safeguarded, see fccqp.admm._anderson."""
    scaling: int = 10
    """Ruiz equilibration iterations (0 disables scaling)."""
    restore_feasibility: bool = True
    """Return a point in the box and the cones: the violating entries are pinned at
    their projection and the others respond through the KKT system, keeping
    ``A x = b``; see :mod:`fccqp.restoration`."""
    kkt_backend: str = "auto"
    """Linear-system backend of the x-update: ``"schur_reduced"`` (Cholesky of ``P + R``
    and of ``A (P + R)^-1 A'``, reduced iteration), ``"ldl_reduced"`` (LDL', reduced
    iteration), ``"ldl_full"`` (LDL', one KKT solve per iteration) or ``"auto"`` (the
    first of these that applies and pays; see docs/algorithm.md). A forced backend
    that cannot factor the matrix falls back to the next one in that order;
    ``Result.backend`` says which ran."""
    warm_start: bool = True
    """Start from the previous solution (used by :class:`fccqp.Solver`)."""
    verbose: bool = False
    """Print one line per residual check."""

    def __post_init__(self) -> None:
        positive = ("rho", "sigma", "eps_prim_inf", "eps_dual_inf", "time_limit")
        for name in positive:
            value = getattr(self, name)
            if not isinstance(value, (int, float)) or isinstance(value, bool) or math.isnan(value):
                raise TypeError(f"setting {name} must be a number, got {value!r}")
            if value <= 0 or (name != "time_limit" and not math.isfinite(value)):
                raise ValueError(f"setting {name} must be finite and > 0, got {value}")
        for name in ("eps_abs", "eps_rel"):
            value = getattr(self, name)
            if not isinstance(value, (int, float)) or isinstance(value, bool):
                raise TypeError(f"setting {name} must be a number, got {value!r}")
            if not (0 <= value < math.inf):
                raise ValueError(f"setting {name} must be finite and >= 0, got {value}")
        if self.eps_abs == 0 and self.eps_rel == 0:
            raise ValueError("settings eps_abs and eps_rel cannot both be 0")
        if not (0 < self.alpha < 2):
            raise ValueError(f"setting alpha must lie in (0, 2), got {self.alpha}")
        if not (self.adaptive_rho_tolerance > 1):
            raise ValueError(
                f"setting adaptive_rho_tolerance must be > 1, got {self.adaptive_rho_tolerance}"
            )
        integers = (
            "max_iter", "check_termination", "adaptive_rho_interval", "scaling", "anderson_memory"
        )
        for name in integers:
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int):
                raise TypeError(f"setting {name} must be an integer, got {value!r}")
            minimum = 0 if name in ("scaling", "anderson_memory") else 1
            if value < minimum:
                raise ValueError(f"setting {name} must be >= {minimum}, got {value}")
        backends = ("auto", "schur_reduced", "ldl_reduced", "ldl_full")
        if self.kkt_backend not in backends:
            raise ValueError(
                f"setting kkt_backend must be one of {', '.join(backends)}, got {self.kkt_backend!r}"
            )
        for name in ("adaptive_rho", "restore_feasibility", "warm_start", "verbose"):
            if not isinstance(getattr(self, name), bool):
                raise TypeError(f"setting {name} must be a bool, got {getattr(self, name)!r}")

    def replace(self, **overrides: object) -> Settings:
        """Return a copy with some fields changed; unknown names raise ``ValueError``."""
        unknown = sorted(set(overrides) - {f.name for f in dataclasses.fields(self)})
        if unknown:
            valid = ", ".join(f.name for f in dataclasses.fields(self))
            raise ValueError(f"unknown setting(s) {', '.join(unknown)}; valid settings: {valid}")
        return dataclasses.replace(self, **overrides)

    @classmethod
    def realtime(cls, **overrides: object) -> Settings:
        """Preset for control loops: warm start, a 15-iteration budget, loose tolerance.

        The paper ran 15 iterations at ``rho = 5e-5`` and ``eps = 1e-4`` on Cassie.
        Here rho applies to the scaled problem and only to constrained entries; a sweep
        over ``rho`` in 0.1-10 on the whole-body-control test sets in ``benchmarks/``
        found no value better than the default 0.1 on every robot (see
        ``docs/performance.md``). Residuals are checked every 5 iterations (each check
        costs about half a KKT solve), so a solve ends after 5, 10 or 15 iterations.
        Anderson acceleration is off: within 15 iterations it changed the p95 torque
        error by -28 % to +16 % across the four robots and cost 12 % of the solve time.
        Ruiz scaling runs 4 passes instead of 10: 20 us less per solve, p95 torque error
        within -9 % to +11 % of 10 passes.
        """
        preset = cls(
            max_iter=15, eps_abs=1e-4, eps_rel=1e-4, warm_start=True, check_termination=5,
            anderson_memory=0, scaling=4,
        )
        return preset.replace(**overrides)
