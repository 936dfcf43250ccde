"""What the report says about the machine: CPU, BLAS and its threads, load, versions.

Timings of sub-millisecond solves depend on the BLAS library and on how many threads
it spins (an OpenBLAS pool on a loaded machine made small fccqp solves 20-50x slower),
and on what else runs: the report records threadpoolctl's view of every BLAS/OpenMP
library in the process, the 1-minute load average at the start and end of the run, and
warns when the load exceeded the core count.
"""

from __future__ import annotations

import os
import platform
import subprocess
from importlib import metadata
from pathlib import Path

from threadpoolctl import threadpool_info

__all__ = ["blas_info", "cpu_model", "git_revision", "load_average", "version"]


def cpu_model() -> str:
    """The CPU's model name (``/proc/cpuinfo``), or the platform's processor string."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def version(package: str) -> str:
    """Installed version of ``package``, or ``not installed``."""
    try:
        return metadata.version(package)
    except metadata.PackageNotFoundError:
        return "not installed"


def git_revision() -> str:
    """Commit of the working tree, with ``+ local changes in src/`` when it is dirty."""
    root = Path(__file__).resolve().parent.parent
    try:
        head = subprocess.run(
            ["git", "rev-parse", "--short", "HEAD"], cwd=root, capture_output=True, text=True,
            check=True,
        ).stdout.strip()
        dirty = subprocess.run(
            ["git", "status", "--porcelain", "--", "src"], cwd=root, capture_output=True,
            text=True, check=True,
        ).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"
    return f"{head} + local changes in src/" if dirty else head


def blas_info() -> list[str]:
    """One line per thread pool threadpoolctl sees: API, library file, version, threads."""
    lines = []
    for pool in threadpool_info():
        detail = ", ".join(
            f"{key} {pool[key]}" for key in ("threading_layer", "architecture") if pool.get(key)
        )
        lines.append(
            f"{pool['internal_api']} {pool.get('version') or ''} "
            f"({Path(pool['filepath']).name}; {pool['num_threads']} threads"
            f"{'; ' + detail if detail else ''})".replace("  ", " ")
        )
    return lines


def load_average() -> float:
    """The 1-minute load average (NaN where the platform has none)."""
    try:
        return os.getloadavg()[0]
    except OSError:
        return float("nan")
