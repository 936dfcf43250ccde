"""fccqp: an ADMM solver for whole-body-control QPs with exact friction cones.

Solves ``min 1/2 x'Px + q'x  s.t.  A x = b, lb <= x <= ub, x[block_k] in K_k`` with the
equalities exact at every iterate and the box and cones handled by projections.
"""

from fccqp.cones import FrictionCone, SecondOrderCone
from fccqp.result import Result
from fccqp.settings import Settings
from fccqp.solver import Solver, solve
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

from fccqp.qpsolvers_backend import register as _register_qpsolvers

_register_qpsolvers()
