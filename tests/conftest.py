"""Every solve test over every KKT backend (issue 28), as OSQP runs its tests over every
linear-system backend.

Two fixtures:

- ``kkt_backend``: one name of :data:`fccqp.settings.KKT_BACKENDS` ("auto" and each
  backend it chooses among, the sparse path included), module-scoped, so that a module's
  tests run backend after backend. A test that asks for it runs once per name, or only
  on the names of its ``kkt_backends`` marker.
- ``every_kkt_backend``: for a module that declares ``pytestmark =
  pytest.mark.usefixtures("every_kkt_backend")``, every :class:`fccqp.Settings` built
  without a ``kkt_backend`` (``fccqp.solve``, ``Solver``, ``Settings.realtime``, the
  qpsolvers and CVXPY adapters) takes the fixture's backend; one given explicitly keeps
  it (as the CVXPY plugin's ``FCCQP``, built at import: test_cvxpy_plugin gives it the
  fixture's default settings). Under "auto" nothing is changed: those are the module's
  tests as they were.

``@pytest.mark.kkt_backends("auto", "ldl_full", reason="...")`` restricts a test to some
backends, the reason saying why: a test of one backend's mechanism (a factorization
count, the reduced table, auto's choice of form), or a heavy test run on "auto" and one
backend of each family.
"""

from __future__ import annotations

import pytest

import fccqp
from fccqp.settings import KKT_BACKENDS


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line(
        "markers", "kkt_backends(*names, reason): the only KKT backends (of "
        "fccqp.settings.KKT_BACKENDS) the test runs on under the kkt_backend fixture, "
        "and why")


def pytest_generate_tests(metafunc: pytest.Metafunc) -> None:
    """Parametrize ``kkt_backend`` over every backend or the marker's."""
    if "kkt_backend" not in metafunc.fixturenames:
        return
    marker = metafunc.definition.get_closest_marker("kkt_backends")
    names = KKT_BACKENDS
    if marker is not None:
        names = marker.args
        unknown = set(names) - set(KKT_BACKENDS)
        if not names or unknown or not marker.kwargs.get("reason"):
            raise ValueError(f"{metafunc.definition.nodeid}: kkt_backends takes names of "
                             f"{KKT_BACKENDS} and a reason, got {marker}")
    metafunc.parametrize("kkt_backend", names, indirect=True, scope="module")


@pytest.fixture(scope="module")
def kkt_backend(request: pytest.FixtureRequest) -> str:
    """The ``kkt_backend`` this test runs on."""
    return request.param


@pytest.fixture(scope="module")
def every_kkt_backend(kkt_backend: str):
    """Make ``kkt_backend`` the default of ``Settings.kkt_backend`` for the module."""
    if kkt_backend == "auto":
        yield kkt_backend
        return
    init = fccqp.Settings.__init__

    def init_on_the_backend(self, *args, **kwargs):
        kwargs.setdefault("kkt_backend", kkt_backend)
        init(self, *args, **kwargs)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(fccqp.Settings, "__init__", init_on_the_backend)
        yield kkt_backend
