"""Load scipy's LAPACK and BLAS tables for Cython without importing ``scipy.linalg``.

The compiled core ``cimport``\\ s ``scipy.linalg.cython_lapack`` and ``cython_blas``: at
first use it needs those two extension modules, which hold function pointers into
scipy's OpenBLAS. Importing them the usual way first imports the ``scipy.linalg``
package, 0.3 s here, which was most of a first solve. Loading the two files directly
and registering them in ``sys.modules`` takes 0.03 s; ``scipy.linalg`` still imports
normally later, reusing them (a hook attaches them to it as attributes). If anything
about the layout differs (another scipy, a frozen application), the normal import runs
instead.
"""

from __future__ import annotations

import importlib.machinery
import importlib.util
import sys
from pathlib import Path
from types import ModuleType

from fccqp._import_hooks import after_import

MODULES = ("scipy.linalg.cython_blas", "scipy.linalg.cython_lapack")


def preload() -> None:
    """Register the two modules, loaded from their files, unless already imported."""
    if "scipy.linalg" in sys.modules or all(name in sys.modules for name in MODULES):
        return
    try:
        spec = importlib.util.find_spec("scipy")
        folder = Path(spec.origin).parent / "linalg"
        for name in MODULES:
            if name in sys.modules:
                continue
            stem = name.rsplit(".", 1)[1]
            path = next(
                folder / (stem + suffix) for suffix in importlib.machinery.EXTENSION_SUFFIXES
                if (folder / (stem + suffix)).exists()
            )
            module_spec = importlib.util.spec_from_file_location(name, path)
            module = importlib.util.module_from_spec(module_spec)
            sys.modules[name] = module
            module_spec.loader.exec_module(module)
        after_import("scipy.linalg", _attach)
    except Exception:  # noqa: BLE001 - any surprise: fall back to the ordinary import
        for name in MODULES:
            sys.modules.pop(name, None)


def _attach(linalg: ModuleType) -> None:
    """Make the preloaded modules attributes of ``scipy.linalg``, as an ordinary import
    of them would have."""
    for name in MODULES:
        setattr(linalg, name.rsplit(".", 1)[1], sys.modules[name])
