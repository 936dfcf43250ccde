"""Test sets: sequences of WBC QPs with Clarabel reference solutions, saved as one npz.

:func:`generate_test_set` rolls sequences of a scenario (or of the ``"mix"`` of all
scenarios) and keeps every QP with its reference solution; :func:`save` and
:func:`load` round-trip a set exactly; :func:`active_fraction` reports how many QPs
have an active friction cone or a saturated torque, the ones that make solvers work.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from benchmarks.robots import ROBOTS, contact_point_names, load_robot
from benchmarks.scenarios import SCENARIOS, make_sequence, rollout
from benchmarks.wbc_qp import WbcQP

__all__ = [
    "GENERATOR_VERSION",
    "CLOSEDLOOP",
    "LAYOUT_NAMES",
    "MIX",
    "TestSet",
    "active_flags",
    "active_fraction",
    "generate_test_set",
    "load",
    "save",
]

GENERATOR_VERSION = 3
"""Version of the generator's output: bump it with any change to ``robots``, ``wbc_qp``,
``scenarios``, this module or, for the ``closedloop`` set, ``benchmarks/closedloop``
that changes the generated QPs, references or records, so
that cached test sets (:mod:`benchmarks.cache`) are generated anew. Version 2 records
each QP's stance (the QPs and references are those of version 1); version 3 keeps
version 2's QPs and solves their references tighter (1e-12 to 1e-11 where version 2
stopped at 1e-9)."""

MIX = "mix"
"""Scenario name of the default mix: sequence ``j`` runs ``SCENARIOS[j % 4]``."""

CLOSEDLOOP = "closedloop"
"""Scenario name of the QPs logged from the MuJoCo closed loop
(:mod:`benchmarks.closedloop.logged`; needs ``mujoco``)."""

LAYOUT_NAMES: tuple[str, ...] = ("vdot", "u", "lambda_h", "eps", "lambda_c")
"""Blocks of ``x``, in order."""

_QP_ARRAYS: tuple[str, ...] = ("P", "q", "A", "b", "lb", "ub", "cone_starts", "mus", "normals")


@dataclass(frozen=True, eq=False)
class TestSet:
    """QPs of one robot and scenario, in controller-loop order.

    Attributes
    ----------
    robot, scenario, seed, dt
        What generated the set (``dt`` is the controller period in seconds).
    qps
        The QPs.
    x_ref
        Clarabel reference solution of each QP, at the tightest tolerance it reaches
        (:func:`benchmarks.wbc_qp.solve_tight_reference`).
    sequence
        Index of the sequence each QP belongs to: a new index is where a controller
        (and a warm start) would restart from rest.
    generator_version
        :data:`GENERATOR_VERSION` of the code that generated the set (0 for files
        written before the version existed).
    stance
        Per QP, the sorted names of the feet in contact (empty for files written before
        version 2): where it changes within a sequence a contact was made or broken.
    """

    __test__ = False  # not a pytest test class

    robot: str
    scenario: str
    seed: int
    dt: float
    qps: list[WbcQP]
    x_ref: list[np.ndarray]
    sequence: np.ndarray
    generator_version: int = 0
    stance: tuple[tuple[str, ...], ...] = ()

    def __len__(self) -> int:
        return len(self.qps)


def generate_test_set(
    robot: str,
    scenario: str,
    n_qps: int,
    seed: int,
    *,
    dt: float = 0.002,
    seq_len: int = 100,
    verbose: bool = False,
) -> TestSet:
    """Generate ``n_qps`` QPs of ``robot`` in sequences of ``seq_len`` ticks.

    Parameters
    ----------
    robot
        A key of :data:`benchmarks.robots.ROBOTS`.
    scenario
        One of :data:`benchmarks.scenarios.SCENARIOS`, ``"mix"`` to cycle through
        them one sequence each, or ``"closedloop"`` for QPs logged from the MuJoCo
        closed loop (:func:`benchmarks.closedloop.logged.logged_sequences`).
    n_qps
        Number of QPs; the last sequence is cut short if needed.
    seed
        Seed; sequence ``j`` draws from ``numpy.random.default_rng([seed, j])``, so a
        set is deterministic and its prefix does not depend on ``n_qps``.
    dt
        Controller period (s).
    seq_len
        Recorded ticks per sequence.
    verbose
        Show a progress bar.
    """
    if scenario not in (MIX, CLOSEDLOOP) and scenario not in SCENARIOS:
        raise ValueError(
            f"unknown scenario {scenario!r}; known: {[*SCENARIOS, MIX, CLOSEDLOOP]}"
        )
    if n_qps < 1 or seq_len < 1:
        raise ValueError(f"n_qps and seq_len must be positive, got {n_qps} and {seq_len}")
    loaded = load_robot(robot)
    qps: list[WbcQP] = []
    xs: list[np.ndarray] = []
    stance: list[tuple[str, ...]] = []
    seq: list[int] = []
    bar = None
    if verbose:
        from tqdm import tqdm

        bar = tqdm(total=n_qps, desc=f"{robot}/{scenario}")
    j = 0
    if scenario == CLOSEDLOOP:  # imported here: only this set needs mujoco
        from benchmarks.closedloop.logged import logged_sequences

        qps, xs, stance, seq = logged_sequences(robot, n_qps, seed, dt, seq_len,
                                                bar.update if bar else None)
    while len(qps) < n_qps:  # the open-loop scenarios (a closedloop set is complete)
        name = SCENARIOS[j % len(SCENARIOS)] if scenario == MIX else scenario
        ticks = min(seq_len, n_qps - len(qps))
        spec = make_sequence(loaded, name, np.random.default_rng([seed, j]), ticks, dt)
        new_qps, new_xs, new_stance = rollout(loaded, spec, dt,
                                              progress=bar.update if bar else None)
        qps += new_qps
        xs += new_xs
        stance += new_stance
        seq += [j] * len(new_qps)
        j += 1
    if bar is not None:
        bar.close()
    return TestSet(robot, scenario, seed, dt, qps, xs, np.array(seq), GENERATOR_VERSION,
                   tuple(stance))


def active_flags(qp: WbcQP, x: np.ndarray, rtol: float = 1e-6) -> tuple[bool, bool]:
    """Whether ``x`` has a friction cone at its boundary and a torque at its limit.

    A cone counts as active when ``mu f_n - ||f_t|| <= rtol ||f||`` for a force that is
    not zero (``||f|| > rtol`` times the largest contact force); a torque when
    ``u_max - |u| <= rtol u_max``.
    """
    cone = False
    if qp.n_contacts:
        f = qp.forces(x)
        fn = np.einsum("ij,ij->i", f, qp.normals)
        ft = np.linalg.norm(f - fn[:, None] * qp.normals, axis=1)
        norm = np.linalg.norm(f, axis=1)
        nonzero = norm > rtol * max(1.0, norm.max())
        cone = bool(np.any(nonzero & (qp.mus * fn - ft <= rtol * norm)))
    u = np.abs(np.asarray(x)[qp.layout["u"]])
    ub = qp.ub[qp.layout["u"]]
    torque = bool(np.any(ub - u <= rtol * ub))
    return cone, torque


def active_fraction(test_set: TestSet, rtol: float = 1e-6) -> float:
    """Fraction of QPs whose reference has an active friction cone or a saturated torque."""
    flags = [
        any(active_flags(qp, x, rtol)) for qp, x in zip(test_set.qps, test_set.x_ref, strict=True)
    ]
    return float(np.mean(flags))


def save(test_set: TestSet, path: str | Path) -> None:
    """Write ``test_set`` to one compressed ``.npz`` (format in docs/benchmarks-generator.md).

    Keys: ``robot``, ``scenario`` (str), ``seed``, ``dt``, ``n_qps``, ``sequence``,
    ``generator_version``, ``stance`` (one str per QP, the feet joined by ``+``), and
    per QP ``i``: ``qp{i}_P``, ``_q``, ``_A``, ``_b``, ``_lb``, ``_ub``, ``_cone_starts``,
    ``_mus``, ``_normals``, ``_nv``, ``_layout`` (5 x 2 ``[start, stop]`` in the order of
    :data:`LAYOUT_NAMES`) and ``_x_ref``.
    """
    arrays: dict[str, np.ndarray] = {
        "robot": np.array(test_set.robot),
        "scenario": np.array(test_set.scenario),
        "seed": np.array(test_set.seed),
        "dt": np.array(test_set.dt),
        "n_qps": np.array(len(test_set)),
        "sequence": np.asarray(test_set.sequence),
        "generator_version": np.array(test_set.generator_version),
        "stance": np.array(["+".join(feet) for feet in test_set.stance], dtype=str),
    }
    for i, (qp, x) in enumerate(zip(test_set.qps, test_set.x_ref, strict=True)):
        for name in _QP_ARRAYS:
            arrays[f"qp{i}_{name}"] = getattr(qp, name)
        arrays[f"qp{i}_nv"] = np.array(qp.nv)
        arrays[f"qp{i}_layout"] = np.array(
            [[qp.layout[k].start, qp.layout[k].stop] for k in LAYOUT_NAMES]
        )
        arrays[f"qp{i}_x_ref"] = x
    np.savez_compressed(path, **arrays)


def load(path: str | Path) -> TestSet:
    """Read a test set written by :func:`save` (no pickles involved). The QPs' contact
    points (:attr:`WbcQP.contacts`) are named from the stance, for a robot of
    :data:`benchmarks.robots.ROBOTS` (:func:`benchmarks.robots.contact_point_names`)."""
    with np.load(path, allow_pickle=False) as z:
        qps, xs = [], []
        robot = str(z["robot"])
        stance = tuple(_feet(str(s)) for s in z["stance"]) if "stance" in z else ()
        named = robot in ROBOTS and len(stance) == int(z["n_qps"])
        for i in range(int(z["n_qps"])):
            layout = {
                k: slice(int(a), int(b))
                for k, (a, b) in zip(LAYOUT_NAMES, z[f"qp{i}_layout"], strict=True)
            }
            fields = {name: z[f"qp{i}_{name}"] for name in _QP_ARRAYS}
            contacts = contact_point_names(robot, stance[i]) if named else ()
            qps.append(WbcQP(**fields, layout=layout, nv=int(z[f"qp{i}_nv"]),
                             contacts=contacts))
            xs.append(z[f"qp{i}_x_ref"])
        return TestSet(
            robot,
            str(z["scenario"]),
            int(z["seed"]),
            float(z["dt"]),
            qps,
            xs,
            z["sequence"],
            int(z["generator_version"]) if "generator_version" in z else 0,
            stance,
        )


def _feet(joined: str) -> tuple[str, ...]:
    """The stance ``save`` wrote as ``"A+B"`` (``""``: no foot down)."""
    return tuple(joined.split("+")) if joined else ()
