"""Run a callback right after a module is imported, without importing it.

fccqp registers itself with qpsolvers when qpsolvers is imported (without paying for
the import in ``import fccqp``), and attaches the LAPACK tables it preloaded to
``scipy.linalg`` when that package is imported (see :mod:`fccqp._scipy_lapack`). Both
use :func:`after_import`: a one-shot finder on ``sys.meta_path`` that finds nothing
itself; for the watched name it asks the other finders and wraps the loader they
return, runs the callback once the module's code has run, and retires.
"""

from __future__ import annotations

import importlib.abc
import sys
from collections.abc import Callable, Sequence
from importlib.machinery import ModuleSpec
from types import ModuleType


class _CallbackLoader(importlib.abc.Loader):
    """Runs the module's own loader, then the callback, and retires the finder."""

    def __init__(self, loader: importlib.abc.Loader, finder: _AfterImport) -> None:
        self._loader = loader
        self._finder = finder

    def create_module(self, spec: ModuleSpec) -> ModuleType | None:
        return self._loader.create_module(spec)

    def exec_module(self, module: ModuleType) -> None:
        # Hand the module its real loader before its code runs, so nothing
        # (submodule imports, importlib.resources, inspect) ever sees this wrapper.
        module.__loader__ = self._loader
        module.__spec__.loader = self._loader
        self._loader.exec_module(module)
        if self._finder in sys.meta_path:
            sys.meta_path.remove(self._finder)
        self._finder.callback(module)


class _AfterImport(importlib.abc.MetaPathFinder):
    """Meta-path finder that wraps the loader of one module name."""

    def __init__(self, name: str, callback: Callable[[ModuleType], object]) -> None:
        self.name = name
        self.callback = callback

    def find_spec(
        self, fullname: str, path: Sequence[str] | None, target: ModuleType | None = None
    ) -> ModuleSpec | None:
        if fullname != self.name:
            return None
        for finder in sys.meta_path:
            find = getattr(finder, "find_spec", None)
            if finder is self or find is None:
                continue
            spec = find(fullname, path, target)
            if spec is not None:
                if spec.loader is not None and hasattr(spec.loader, "exec_module"):
                    spec.loader = _CallbackLoader(spec.loader, self)
                return spec
        return None


def after_import(name: str, callback: Callable[[ModuleType], object]) -> None:
    """Call ``callback(module)`` right after ``import name`` completes (once; now, if
    the module is imported already). Calling it again for the same name is harmless."""
    if name in sys.modules:
        callback(sys.modules[name])
        return
    if not any(isinstance(f, _AfterImport) and f.name == name for f in sys.meta_path):
        sys.meta_path.insert(0, _AfterImport(name, callback))
