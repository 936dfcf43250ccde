"""The result of a solve."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fccqp.status import Status


@dataclass(frozen=True)
class Result:
    """Primal and dual solution with diagnostics.

    Sign convention (the same as qpsolvers' for the box):
    ``P x + q + A' y + z = 0``. For a box entry ``z_i < 0`` where the lower bound is
    active and ``z_i > 0`` where the upper bound is; for a cone block ``-z_block``
    lies in the dual cone. Entries with no bound and no cone have ``z_i = 0``.

    When the status is :attr:`Status.PRIMAL_INFEASIBLE`, ``certificate`` holds the
    dual direction ``(y, z)`` concatenated; for :attr:`Status.DUAL_INFEASIBLE` it holds
    the primal direction ``dx``; otherwise it is ``None``.
    """

    x: np.ndarray
    """Primal solution (or last iterate)."""
    y: np.ndarray
    """Multipliers of ``A x = b``."""
    z: np.ndarray
    """Multipliers of the box and cone constraints, one per entry of ``x``."""
    status: Status
    """How the solve ended."""
    obj: float
    """Objective ``1/2 x'Px + q'x`` at ``x``."""
    iterations: int
    """ADMM iterations performed (with those of the auxiliary solves that certified a
    stalled run, see :mod:`fccqp.auxiliary`)."""
    prim_res: float
    """Primal residual of the returned ``x``: ``max(||Ax - b||, ||x_S - P_C(x_S)||)``
    (infinity norm), the second term its largest distance to the box and the cones."""
    dual_res: float
    """Dual residual ``||Px + q + A'y + z||`` of the returned point (infinity norm)."""
    setup_time: float
    """Seconds spent validating, scaling and factorizing before the iterations."""
    solve_time: float
    """Seconds spent in the whole call."""
    rho: float
    """Final rho (scaled problem)."""
    factorizations: int
    """Factorizations of the x-update's KKT matrix performed during the call (0 when a
    warm solve reused it); polishing's factorizations of its own, smaller system are
    not counted."""
    certificate: np.ndarray | None = None
    """Infeasibility certificate, see the class docstring."""
    backend: str = ""
    """KKT backend of the last factorization (see ``Settings.kkt_backend``)."""
    gap: float = float("nan")
    """Duality gap ``|x'Px + q'x + b'y + sigma_C(z)|`` of the returned point, ``sigma_C``
    the support function of the box and cones (see docs/formulation.md); NaN when the
    status is an infeasibility certificate."""
    polished: bool = False
    """True when the returned point is the polished one (``Settings.polish``): the
    exact solution of the QP on the guessed active set, which passed the KKT check on
    the user's problem; False when polishing was off, failed or was rejected."""

    @classmethod
    def _of(cls, fields: dict[str, object]) -> Result:
        """A result with every field given in ``fields``, without the frozen
        dataclass's ``__init__``, which sets each field through ``object.__setattr__``:
        34k instructions per solve against 11k (callgrind), a quarter of the Python
        layer of a go2 solve."""
        result = object.__new__(cls)
        result.__dict__.update(fields)
        return result
