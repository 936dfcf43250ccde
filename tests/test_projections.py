"""Properties of the cone projections: membership, idempotence, Moreau decomposition."""

import numpy as np
import pytest
from fccqp.projections import (
    project_cone_block,
    project_constraint_set,
    project_friction_cone,
    project_second_order_cone,
    touching_point,
)
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from fccqp.cones import FRICTION, KINDS, SECOND_ORDER

finite = st.floats(-1e3, 1e3, allow_nan=False, allow_infinity=False)
mus = st.floats(1e-3, 1e3)
vectors3 = arrays(np.float64, 3, elements=finite)


def unit(v):
    return v / np.linalg.norm(v)


normals = arrays(np.float64, 3, elements=st.floats(-1, 1)).filter(
    lambda v: np.linalg.norm(v) > 0.1
).map(unit)


UP = np.array([0.0, 0.0, 1.0])


def friction(v, mu, normal=UP):
    out = np.empty(3)
    project_friction_cone(v, mu, normal, out)
    return out


def soc(v):
    out = np.empty_like(v)
    project_second_order_cone(v, out)
    return out


def friction_violation(f, mu, normal):
    fn = normal @ f
    return np.linalg.norm(f - fn * normal) - mu * fn


@settings(max_examples=300, deadline=None)
@given(vectors3, mus, normals)
def test_friction_projection_lands_in_cone_and_is_idempotent(v, mu, normal):
    p = friction(v, mu, normal)
    scale = 1 + np.linalg.norm(v)
    assert friction_violation(p, mu, normal) <= 1e-9 * scale * (1 + mu)
    np.testing.assert_allclose(friction(p, mu, normal), p, atol=1e-9 * scale)


@settings(max_examples=300, deadline=None)
@given(vectors3, mus, normals)
def test_friction_moreau_decomposition(v, mu, normal):
    """v = P_K(v) + P_K°(v) with K° = -K*, K* the friction cone with 1/mu; parts orthogonal."""
    p = friction(v, mu, normal)
    polar = -friction(-v, 1 / mu, normal)
    scale = 1 + np.linalg.norm(v)
    np.testing.assert_allclose(p + polar, v, atol=1e-8 * scale)
    assert abs(p @ polar) <= 1e-8 * scale**2


@settings(max_examples=200, deadline=None)
@given(arrays(np.float64, st.integers(2, 8), elements=finite))
def test_second_order_cone_properties(v):
    p = soc(v)
    polar = -soc(-v)
    scale = 1 + np.linalg.norm(v)
    assert np.linalg.norm(p[1:]) <= p[0] + 1e-9 * scale
    np.testing.assert_allclose(soc(p), p, atol=1e-9 * scale)
    np.testing.assert_allclose(p + polar, v, atol=1e-8 * scale)
    assert abs(p @ polar) <= 1e-8 * scale**2


@settings(max_examples=200, deadline=None)
@given(vectors3, mus, vectors3)
def test_friction_projection_is_nearest_point(v, mu, w):
    """No sampled cone point is closer to v than the projection."""
    p = friction(v, mu)
    candidate = friction(w, mu)
    assert np.linalg.norm(v - p) <= np.linalg.norm(v - candidate) + 1e-9 * (1 + np.abs(v).max())


def test_zero_normal_force_with_tangential_force():
    """The original C++ returned 0 here; the answer is on the cone boundary."""
    np.testing.assert_allclose(
        friction(np.array([1.0, 0.5, 0.0]), 0.7), [0.3288, 0.1644, 0.5252], atol=1e-4
    )


@pytest.mark.parametrize(
    "v, mu, expected",
    [
        (np.zeros(3), 0.5, np.zeros(3)),
        (np.array([0.0, 0.0, 2.0]), 0.5, [0.0, 0.0, 2.0]),
        (np.array([0.0, 0.0, -2.0]), 0.5, np.zeros(3)),
        (np.array([3.0, 4.0, 0.0]), 1e-12, [0.0, 0.0, 5e-12]),
        (np.array([3.0, 4.0, -1.0]), 1e300, [3.0, 4.0, 0.0]),
        (np.array([3.0, 4.0, 1.0]), 1e300, [3.0, 4.0, 1.0]),
    ],
)
def test_friction_edge_cases(v, mu, expected):
    np.testing.assert_allclose(friction(v, mu), expected, atol=1e-12)


def test_tilted_normal_matches_rotated_flat_cone():
    rng = np.random.default_rng(0)
    Q, _ = np.linalg.qr(rng.standard_normal((3, 3)))
    normal = Q[:, 2]
    for _ in range(50):
        v = rng.standard_normal(3) * 3
        np.testing.assert_allclose(
            friction(v, 0.6, normal), Q @ friction(Q.T @ v, 0.6), atol=1e-12
        )


def test_constraint_set_clips_box_and_projects_cones_in_place():
    v = np.array([5.0, -5.0, 1.0, 0.5, 0.0, 3.0, 4.0])
    lo = np.array([-1.0, -1.0, -np.inf, -np.inf, -np.inf, -np.inf, -np.inf])
    hi = np.array([1.0, 1.0, np.inf, np.inf, np.inf, np.inf, np.inf])
    cones = (
        np.array([FRICTION, SECOND_ORDER]), np.array([2, 5]), np.array([3, 2]),
        np.array([0.7, 0.0]), np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 0.0]]),
    )
    expected = np.empty(7)
    expected[:2] = [1.0, -1.0]
    project_cone_block(v[2:5], FRICTION, 0.7, np.array([0.0, 0.0, 1.0]), expected[2:5])
    expected[5:] = [3.5, 3.5]
    project_constraint_set(v, lo, hi, cones, v)
    np.testing.assert_allclose(v, expected)


def test_every_registered_kind_has_its_code_in_the_compiled_core():
    """fccqp.cones.KINDS and the compiled registry (cone_dispatch.pxd) agree on the codes:
    each kind's code projects a block of its size as that kind, and sizes the kind
    cannot have, or codes no kind has, are rejected."""
    v = np.array([0.9, -0.4, 0.3])
    own = {FRICTION: friction(v, 0.5), SECOND_ORDER: soc(v)}
    assert sorted(kind.code for kind in KINDS) == sorted(own)
    for kind in KINDS:
        out = np.empty(3)
        project_cone_block(v, kind.code, 0.5, UP, out)
        np.testing.assert_array_equal(out, own[kind.code])
    with pytest.raises(ValueError, match="cannot have 4 entries"):
        project_cone_block(np.ones(4), FRICTION, 0.5, UP, np.empty(4))
    with pytest.raises(ValueError, match="kind 7"):
        project_cone_block(v, 7, 0.5, UP, np.empty(3))


@pytest.mark.parametrize("kind, dim", [(FRICTION, 3), (SECOND_ORDER, 2), (SECOND_ORDER, 5)])
def test_the_tangent_plane_touches_the_cone_on_the_ray_of_its_point(kind, dim):
    """``cone_touch`` of the plane at a boundary point, with that point's axis part, is
    the point itself; from a point off the cone, it lies on the boundary and on the
    plane (the polish gives a plane its curvature there)."""
    rng = np.random.default_rng(0)
    for _ in range(50):
        normal = rng.standard_normal(3)
        normal /= np.linalg.norm(normal)
        mu = rng.uniform(0.1, 2.0)
        v = rng.standard_normal(dim)
        on, out = np.empty(dim), np.empty(dim)
        project_cone_block(v, kind, mu, normal, on)
        if _phi(v, kind, mu, normal) <= 0.0 or not touching_point(on, kind, mu, normal, out):
            continue   # v in the cone, or its projection is the apex
        np.testing.assert_allclose(out, on, atol=1e-12 * np.linalg.norm(on))
        off = on + rng.standard_normal(dim)
        if _split(off, kind, normal)[0] > 0.0 and touching_point(off, kind, mu, normal, out):
            assert abs(_phi(out, kind, mu, normal)) <= 1e-12 * np.linalg.norm(out)
            assert abs(_plane_gap(off, out, kind, mu, normal)) <= 1e-12 * np.linalg.norm(out)


def _split(v, kind, normal):
    """The axis part of ``v`` and the norm of the rest."""
    if kind == FRICTION:
        along = normal @ v
        return along, np.linalg.norm(v - along * normal)
    return v[0], np.linalg.norm(v[1:])


def _phi(v, kind, mu, normal):
    """The cone function ``across - slope * along``."""
    along, across = _split(v, kind, normal)
    return across - (mu if kind == FRICTION else 1.0) * along


def _plane_gap(at, v, kind, mu, normal):
    """``g'v`` for ``g`` the cone function's gradient at ``at`` (unnormalized)."""
    along, across = _split(at, kind, normal)
    if kind == FRICTION:
        g = (at - along * normal) / across - mu * normal
    else:
        g = np.concatenate([[-1.0], at[1:] / across])
    return g @ v
