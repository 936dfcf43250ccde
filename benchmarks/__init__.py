"""Whole-body-control QP test sets from real robot models, for benchmarking fccqp.

The generator (``robots``, ``wbc_qp``, ``scenarios``, ``testsets``) builds the
operational-space-control QPs of the FCCQP paper (section 4, eq. 10) with Pinocchio
and the models of ``example-robot-data``, and solves them with Clarabel for reference.
It does not depend on ``fccqp``, so the test sets stay an independent yardstick.
"""
