"""Closed-loop benchmark: each solver drives a simulated robot in MuJoCo (issue #31).

The whole-body-control QP of :mod:`benchmarks.wbc_qp` runs in a loop against MuJoCo:
the controller reads the simulated state, builds the QP, one solver answers it and the
answer's torques drive the simulation until the next control tick. Modules, one job
each: :mod:`~benchmarks.closedloop.model` (MuJoCo model from the Pinocchio one, state
conversion), :mod:`~benchmarks.closedloop.scenarios` (contact schedules, references,
pushes), :mod:`~benchmarks.closedloop.controller` (task PD and QP),
:mod:`~benchmarks.closedloop.simulate` (the loop), :mod:`~benchmarks.closedloop.metrics`,
:mod:`~benchmarks.closedloop.plots`, :mod:`~benchmarks.closedloop.report`,
:mod:`~benchmarks.closedloop.logged` (closed-loop QPs as an open-loop test set) and
:mod:`~benchmarks.closedloop.cli` (``python -m benchmarks closedloop``). See
docs/closedloop.md.
"""
