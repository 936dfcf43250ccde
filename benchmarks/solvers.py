"""The registry of benchmarked variants: which solver, at which setting, on which cones.

A variant is one solver at one setting (:class:`Variant`). Each peer runs at its own
default settings and, for the work-precision plot, at one looser and one tighter
tolerance (the ``-loose`` / ``-tight`` variants, ``sweep=True``); fccqp runs its two
presets plus a sweep of its tolerance and of the real-time preset's time budget.
The table :data:`VARIANTS` is the single source of names, descriptions and classes;
the adapters are in :mod:`benchmarks.exact_solvers` and :mod:`benchmarks.pyramid_solvers`.

Tolerances of the sweep: interior-point solvers (Clarabel, QOCO, PIQP) loose at 1000x
and tight at 1/100 of their default; first-order and active-set solvers (OSQP, ProxQP,
DAQP) loose at 10x-100x and tight at 1/100-1/1000; SCS tight at 1/10 only (at 1e-6 it
took 60 ms per talos_reduced QP, a third of a quick run); quadprog has no tolerance.
"""

from __future__ import annotations

import importlib.util
from collections.abc import Callable
from dataclasses import dataclass

from benchmarks.adapters import Adapter
from benchmarks.exact_solvers import ClarabelAdapter, FccqpAdapter, QocoAdapter, ScsAdapter
from benchmarks.pyramid_solvers import (
    DaqpAdapter,
    OsqpAdapter,
    PiqpAdapter,
    ProxqpAdapter,
    QpsolversAdapter,
    QuadprogAdapter,
)

__all__ = ["VARIANTS", "Variant", "available_variants", "make_adapter"]


@dataclass(frozen=True)
class Variant:
    """One solver at one setting.

    Attributes
    ----------
    name
        Variant name (CLI, tables, CSV).
    family
        The solver, which fixes its colour and marker in every plot.
    setting
        Short label of the setting (``default``, ``loose``, ``tight``, ``eps 1e-3``, ...).
    exact_cones
        Whether the solver sees the exact friction cones (else a 4- or 8-facet inner
        pyramid).
    direct
        Whether the solver is called through its own Python API (else through
        qpsolvers).
    sweep
        Whether the variant is a point of a settings sweep rather than a solver's default
        (sweep points appear in the work-precision and deadline views only).
    module
        Python module whose presence makes the variant available.
    factory
        Builds a fresh adapter, given the variant name.
    description
        One line for the report.
    """

    name: str
    family: str
    setting: str
    exact_cones: bool
    direct: bool
    sweep: bool
    module: str
    factory: Callable[[str], Adapter]
    description: str


def _fccqp(name: str, setting: str, sweep: bool, overrides: dict, realtime: bool,
           description: str) -> Variant:
    def factory(variant: str) -> Adapter:
        import fccqp

        make = fccqp.Settings.realtime if realtime else fccqp.Settings
        return FccqpAdapter(variant, make(**overrides))

    return Variant(name, "fccqp", setting, True, True, sweep, "fccqp", factory, description)


def _tolerances(name: str, family: str, exact: bool, module: str,
                make: Callable[[str, float | None], Adapter], knob: str,
                tolerances: tuple[float, float, float], start: str) -> list[Variant]:
    """A peer at its default tolerance and at a looser and a tighter one.

    ``tolerances`` are (default, loose, tight); ``start`` says how it starts a solve.
    """
    cones = "exact cones" if exact else "4-facet inner pyramid"
    default, loose, tight = tolerances
    out = [Variant(name, family, "default", exact, True, False, module, lambda v: make(v, None),
                   f"{family} defaults ({knob} {default:.0e}), {cones}, {start}")]
    for label, tol in (("loose", loose), ("tight", tight)):
        out.append(Variant(f"{name}-{label}", family, label, exact, True, True, module,
                           lambda v, tol=tol: make(v, tol),
                           f"{family}, {knob} {tol:.0e}, {cones}, {start}"))
    return out


_LIST: list[Variant] = [
    _fccqp("fccqp-realtime", "realtime", False, {}, True,
           "fccqp, Settings.realtime() (2 ms budget, polishing, eps 1e-4), exact cones, warm"),
    _fccqp("fccqp-realtime-nopolish", "realtime, no polish", True, {"polish": False}, True,
           "fccqp, Settings.realtime(polish=False), exact cones, warm"),
    _fccqp("fccqp-default", "default", False, {}, False,
           "fccqp, Settings() (eps 1e-5), exact cones, warm"),
    *[
        _fccqp(f"fccqp-eps{eps:.0e}".replace("e-0", "e-"), f"eps {eps:.0e}", True,
               {"eps_abs": eps, "eps_rel": eps}, False,
               f"fccqp, Settings(eps_abs=eps_rel={eps:.0e}), exact cones, warm")
        for eps in (1e-3, 1e-4, 1e-6, 1e-7)
    ],
    *[
        _fccqp(f"fccqp-realtime-{ms:g}ms", f"realtime, {ms:g} ms", True, {"budget": ms * 1e-3},
               True, f"fccqp, Settings.realtime(budget={ms * 1e-3:g}), exact cones, warm")
        for ms in (0.5, 1, 3)
    ],
    *_tolerances("clarabel", "clarabel", True, "clarabel", ClarabelAdapter,
                 "tol_gap_abs = tol_gap_rel = tol_feas", (1e-8, 1e-5, 1e-10),
                 "cold (no warm start)"),
    *_tolerances("qoco", "qoco", True, "qoco", QocoAdapter, "abstol = reltol",
                 (1e-7, 1e-4, 1e-9), "cold (no warm start in its Python API)"),
    *_tolerances("scs", "scs", True, "scs", ScsAdapter, "eps_abs = eps_rel", (1e-4, 1e-3, 1e-5),
                 "warm (previous x, y, s)"),
    *_tolerances("daqp-pyr4", "daqp", False, "daqp", DaqpAdapter, "primal_tol",
                 (1e-6, 1e-4, 1e-9), "warm (previous multipliers)"),
    Variant("quadprog-pyr4", "quadprog", "default", False, True, False, "quadprog",
            QuadprogAdapter, "quadprog (no settings), 4-facet inner pyramid, cold"),
    *_tolerances("piqp-pyr4", "piqp", False, "piqp", PiqpAdapter,
                 "eps_abs (eps_rel = eps_abs / 10)",
                 (1e-8, 1e-5, 1e-10), "cold (no warm start)"),
    *_tolerances("proxqp-pyr4", "proxqp", False, "proxsuite",
                 lambda v, eps: ProxqpAdapter(v, 4, eps), "eps_abs", (1e-5, 1e-3, 1e-8),
                 "warm (update)"),
    Variant("proxqp-pyr8", "proxqp", "8 facets", False, True, False, "proxsuite",
            lambda v: ProxqpAdapter(v, 8), "proxqp defaults, 8-facet inner pyramid, warm (update)"),
    *_tolerances("osqp-pyr4", "osqp", False, "osqp", lambda v, eps: OsqpAdapter(v, 4, eps),
                 "eps_abs = eps_rel", (1e-3, 1e-2, 1e-5),
                 "warm (warm_start x, y)"),
    Variant("osqp-pyr8", "osqp", "8 facets", False, True, False, "osqp",
            lambda v: OsqpAdapter(v, 8),
            "osqp defaults, 8-facet inner pyramid, warm (warm_start x, y)"),
    *[
        Variant(f"qpsolvers:{s}", s, "via qpsolvers", False, False, False, "qpsolvers",
                lambda v, s=s: QpsolversAdapter(v, s),
                f"qpsolvers.solve_problem(solver={s!r}) defaults, 4-facet inner pyramid, cold")
        for s in ("fccqp", "proxqp", "osqp", "clarabel")
    ],
]

VARIANTS: dict[str, Variant] = {v.name: v for v in _LIST}
"""Variant name -> :class:`Variant`, in report order."""


def _installed(variant: Variant) -> bool:
    if importlib.util.find_spec(variant.module) is None:
        return False
    if variant.direct:
        return True
    import qpsolvers

    import fccqp  # noqa: F401  (registers the "fccqp" backend of qpsolvers)

    return variant.family in qpsolvers.available_solvers


def available_variants(names: list[str]) -> tuple[list[str], list[str]]:
    """Split ``names`` into the installed variants and the missing ones."""
    found = [name for name in names if _installed(VARIANTS[name])]
    return found, [name for name in names if name not in found]


def make_adapter(name: str) -> Adapter:
    """A fresh adapter of variant ``name``."""
    return VARIANTS[name].factory(name)
