"""fccqp: an ADMM solver for whole-body-control QPs with exact friction cones.

Solves ``min 1/2 x'Px + q'x  s.t.  A x = b, lb <= x <= ub, x[block_k] in K_k`` with the
equalities exact at every iterate and the box and cones handled by projections.

``Solver`` and ``solve`` load the compiled core (and scipy's LAPACK tables) on first
access, so that ``import fccqp`` stays cheap.
"""

from fccqp.cones import FrictionCone, SecondOrderCone
from fccqp.qpsolvers_backend import register as _register_qpsolvers
from fccqp.result import Result
from fccqp.settings import Settings
from fccqp.status import Status

__all__ = [
    "FrictionCone",
    "Result",
    "SecondOrderCone",
    "Settings",
    "Solver",
    "Status",
    "solve",
]
__version__ = "0.1.0"

_LAZY = ("Solver", "solve")


def __getattr__(name: str) -> object:
    if name in _LAZY:
        from fccqp._scipy_lapack import preload

        preload()
        from fccqp import solver

        return getattr(solver, name)
    raise AttributeError(f"module 'fccqp' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(list(globals()) + list(_LAZY))


_register_qpsolvers()
