"""Run the fuzzer of tests/fuzzing.py over many seeds and count what fails.

    python tools/fuzz_campaign.py --cases 3000 --seed 0 [--backend NAME]
        [--classes feasible,cvxpy] [--out FILE] [--jobs 2]
    python tools/fuzz_campaign.py --cases 900 --seed 0 --classes degenerate
    python tools/fuzz_campaign.py --replay feasible:17 [--backend NAME]

Case ``i`` of a campaign is class ``classes[i % len(classes)]`` with seed ``seed + i //
len(classes)``, so the classes share the cases evenly and a campaign is the same on
every run. The summary gives, per class, the cases, the failures by kind, fccqp's
outcomes and the cases where Clarabel contradicted the construction (no reference
then); ``--out`` writes one JSON line per failing case (``case``, ``class``, ``seed``,
``backend``, ``description``), which ``--replay class:seed`` runs again and explains.
Without ``--classes`` a campaign runs issue 26's eight classes
(``fuzzing.CAMPAIGN_CLASSES``), so a seed names the cases it always named; the
``degenerate`` class runs when named.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections import Counter, defaultdict
from multiprocessing import Pool
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "tests"), str(ROOT)]

import fuzzing  # noqa: E402 - found through the path set just above
from fccqp.settings import KKT_BACKENDS  # noqa: E402


def _run(job: tuple[str, int, str]) -> tuple[str, int, fuzzing.Verdict, float]:
    name, seed, backend = job
    start = time.perf_counter()
    verdict = fuzzing.judge_case(fuzzing.Case.of(name, seed), backend)
    return name, seed, verdict, time.perf_counter() - start


def campaign(cases: int, seed: int, backend: str, classes: list[str], out: Path | None,
             jobs: int) -> int:
    """Run the campaign, print its summary, write the failures; return their number."""
    work = [(classes[i % len(classes)], seed + i // len(classes), backend)
            for i in range(cases)]
    per_class: dict[str, Counter] = defaultdict(Counter)
    outcomes: dict[str, Counter] = defaultdict(Counter)
    kinds: Counter = Counter()
    failures = []
    started = time.perf_counter()
    fuzzing.fccqp.Solver  # noqa: B018 - load the compiled core before the workers fork
    with Pool(jobs) if jobs > 1 else _Serial() as pool:
        for name, case_seed, verdict, seconds in pool.imap(_run, work, chunksize=4):
            counts = per_class[name]
            counts["cases"] += 1
            counts["seconds"] += seconds
            counts["conflicts"] += verdict.conflict
            outcomes[name][verdict.outcome] += 1
            if verdict.failure is not None:
                counts[verdict.kind] += 1
                kinds[verdict.kind] += 1
                failures.append({"case": f"{name}:{case_seed}", "class": name,
                                 "seed": case_seed, "backend": backend,
                                 "description": verdict.failure})
    print(f"{cases} cases, seeds from {seed}, backend {backend}, "
          f"{time.perf_counter() - started:.0f} s, {len(failures)} failures")
    print(f"{'class':<18} {'cases':>5} {'fail':>5}  by kind / fccqp outcomes / conflicts")
    for name in classes:
        counts = per_class[name]
        failed = {k: v for k, v in counts.items()
                  if k not in ("cases", "seconds", "conflicts")}
        print(f"{name:<18} {counts['cases']:>5} {sum(failed.values()):>5}  "
              f"{dict(sorted(failed.items()))} / {dict(outcomes[name].most_common())} / "
              f"{counts['conflicts']} ({counts['seconds']:.0f} s)")
    print("failures by kind:", dict(kinds.most_common()))
    if out is not None:
        with out.open("w") as stream:
            for failure in failures:
                stream.write(json.dumps(failure) + "\n")
        print(f"failing cases written to {out}")
    return len(failures)


class _Serial:
    """``Pool``'s ``imap`` in this process (``--jobs 1``): tracebacks stay readable."""

    def __enter__(self) -> _Serial:
        return self

    def __exit__(self, *exc: object) -> None:
        return None

    def imap(self, function, items, chunksize: int = 1):
        return map(function, items)


def replay(text: str, backend: str) -> int:
    """Judge one ``class:seed`` case again and print what it is and what happened."""
    case = fuzzing.Case.parse(text)
    scenario = case.scenario()
    print(f"{case} on {backend}: {type(scenario).__name__}: {getattr(scenario, 'what', '')}")
    verdict = fuzzing.judge_case(case, backend)
    print(f"outcome {verdict.outcome}, reference {verdict.reference}, "
          f"conflict {verdict.conflict}")
    print("failure:", verdict.failure)
    return verdict.failure is not None


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cases", type=int, default=300, help="number of cases")
    parser.add_argument("--seed", type=int, default=0, help="first seed of every class")
    parser.add_argument("--backend", default="auto", choices=KKT_BACKENDS)
    parser.add_argument("--classes", default=",".join(fuzzing.CAMPAIGN_CLASSES),
                        help="comma-separated classes (default: issue 26's eight; "
                             f"known: {', '.join(fuzzing.CLASSES)})")
    parser.add_argument("--out", type=Path, help="JSON-lines file for the failing cases")
    parser.add_argument("--jobs", type=int, default=1, help="worker processes")
    parser.add_argument("--replay", metavar="CLASS:SEED", help="judge one case again")
    args = parser.parse_args(argv)
    if args.replay:
        return replay(args.replay, args.backend)
    classes = args.classes.split(",")
    unknown = sorted(set(classes) - set(fuzzing.CLASSES))
    if unknown:
        parser.error(f"unknown classes {unknown}; known: {', '.join(fuzzing.CLASSES)}")
    failed = campaign(args.cases, args.seed, args.backend, classes, args.out, args.jobs)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
