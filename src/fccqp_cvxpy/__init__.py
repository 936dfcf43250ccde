"""CVXPY plugin of fccqp: ``problem.solve(solver=FCCQP)``.

``FCCQP`` is a ready solver instance (CVXPY takes instances); ``FCCQP(eps_abs=1e-7)``
returns one with other default settings. Importing this package also registers
``FCCQP`` under the name ``"FCCQP"`` in CVXPY's conic solver map, so
``problem.solve(solver="FCCQP")`` works too (CVXPY 1.9 no longer adds solver
instances to its name map by itself).
"""

from cvxpy.reductions.solvers import defines

from fccqp_cvxpy.solver import FCCQP, FCCQPSolver

defines.SOLVER_MAP_CONIC.setdefault(FCCQP.name(), FCCQP)

__all__ = ["FCCQP", "FCCQPSolver"]
