"""Calls and inclusive instructions of named functions in a callgrind output file.

``python tools/activeset_callgrind/calls.py FILE NAME ...``: for each ``NAME`` (a
function's symbol, e.g. ``scipy_dsytrf_``), the calls to it and their inclusive
instructions summed over all call sites, and the mean per call; read from the call
arcs (``cfn=`` / ``calls=`` lines), so it works on files recorded with
``--toggle-collect`` too.
"""

import re
import sys
from collections import defaultdict


def main(path: str, names: list[str]) -> None:
    ids: dict[str, str] = {}
    calls: dict[str, int] = defaultdict(int)
    cost: dict[str, int] = defaultdict(int)
    callee, pending = None, None
    with open(path) as fh:
        for line in fh:
            if line.startswith(("fn=", "cfn=")):
                key, rest = line.rstrip("\n").split("=", 1)
                m = re.match(r"\((\d+)\)(?: (.*))?", rest)
                name = rest
                if m:
                    if m.group(2):
                        ids[m.group(1)] = m.group(2)
                    name = ids.get(m.group(1), rest)
                if key == "cfn":
                    callee = name.split(" ")[0].split("'")[0]
            elif line.startswith("calls="):
                pending = int(line.split("=")[1].split()[0])
            elif pending is not None:
                parts = line.split()
                if callee in names:
                    calls[callee] += pending
                    cost[callee] += int(parts[1]) if len(parts) > 1 else 0
                pending = None
    for n in names:
        print(f"{n}: {calls[n]} calls, {cost[n]} instructions, "
              f"{cost[n] / max(calls[n], 1):.0f} per call")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2:])
