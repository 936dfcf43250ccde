"""Solver variants of the closed loop: the open-loop registry plus OSQP at the paper's settings.

The FCCQP paper's walking experiments ran OSQP with the hyperparameters of its Table 2:
rho 1e-4, eps_abs = eps_rel = 1e-7, eps_prim_inf = eps_dual_inf = 1e-5, at most 100
iterations, qdldl, rho adaptation, solution polishing and warm starting. ``osqp-paper``
is that OSQP on the 4-facet inner pyramid (the problem ``osqp-pyr4`` sees), warm started
the same way. It only exists here: the open-loop benchmark's registry
(:data:`benchmarks.solvers.VARIANTS`) is left as it is.
"""

from __future__ import annotations

import importlib.util

from benchmarks.adapters import Adapter
from benchmarks.pyramid_solvers import OsqpAdapter
from benchmarks.solvers import VARIANTS, Variant, available_variants, make_adapter

__all__ = ["CLOSEDLOOP_VARIANTS", "PAPER_OSQP", "available", "lookup", "make"]

PAPER_OSQP: dict[str, object] = {
    "rho": 1e-4, "eps_abs": 1e-7, "eps_rel": 1e-7, "eps_prim_inf": 1e-5,
    "eps_dual_inf": 1e-5, "max_iter": 100, "adaptive_rho": True, "polishing": True,
    "warm_starting": True,
}
"""OSQP's settings in the FCCQP paper's Table 2 (OSQP 1.x names)."""


class PaperOsqpAdapter(OsqpAdapter):
    """:class:`~benchmarks.pyramid_solvers.OsqpAdapter` with :data:`PAPER_OSQP`."""

    def __init__(self, name: str) -> None:
        super().__init__(name, 4)
        self._settings |= PAPER_OSQP


CLOSEDLOOP_VARIANTS: dict[str, Variant] = {
    "osqp-paper": Variant(
        "osqp-paper", "osqp", "paper Table 2", False, True, False, "osqp", PaperOsqpAdapter,
        "osqp at the FCCQP paper's Table 2 settings (rho 1e-4, eps 1e-7, 100 iterations, "
        "polishing), 4-facet inner pyramid, warm (warm_start x, y)"),
}
"""Variants only the closed loop runs."""


def lookup(name: str) -> Variant:
    """The variant ``name``, of the closed loop or of the open-loop registry."""
    return CLOSEDLOOP_VARIANTS.get(name) or VARIANTS[name]


def make(name: str) -> Adapter:
    """A fresh adapter of variant ``name``."""
    if name in CLOSEDLOOP_VARIANTS:
        return CLOSEDLOOP_VARIANTS[name].factory(name)
    return make_adapter(name)


def available(names: list[str]) -> tuple[list[str], list[str]]:
    """Split ``names`` into installed variants and missing ones (order kept)."""
    extra = [n for n in names if n in CLOSEDLOOP_VARIANTS]
    found, missing = available_variants([n for n in names if n not in CLOSEDLOOP_VARIANTS])
    found += [n for n in extra if importlib.util.find_spec(CLOSEDLOOP_VARIANTS[n].module)]
    missing += [n for n in extra if n not in found]
    return [n for n in names if n in found], missing
