"""Euclidean projections onto the constraint set, compiled with numba.

The set is a box on every constrained entry times cones on disjoint blocks (see
:mod:`fccqp.cones`). Cone entries carry infinite box bounds, so one kernel clips the
whole vector and then projects each cone block.

The polar of a closed convex cone ``K`` is ``K° = -K*``; by Moreau's decomposition
``v = P_K(v) + P_K°(v)``, so a distance to ``K°`` is the norm of ``P_K(v)`` and a
projection onto ``K°`` is ``v - P_K(v)``: :func:`project_cone_block` serves both.
The dual of the friction cone with coefficient ``mu`` is the friction cone with
coefficient ``1/mu`` about the same normal; second-order cones are self-dual.
"""

import math

from numba import njit

from fccqp.cones import FRICTION


@njit(cache=True)
def project_friction_cone(v, mu, normal, out):
    """Project the 3-vector ``v`` onto ``{f : ||f - (n'f)n|| <= mu n'f}`` into ``out``.

    With ``f_n = n'v`` and tangential part ``t = v - f_n n`` of norm ``a``:
    inside the cone (``a <= mu f_n``) ``v`` is kept; inside the polar
    (``mu a <= -f_n``) the answer is 0; otherwise ``v`` lands on the ray through
    ``(mu t/a, 1)``: normal part ``(mu a + f_n)/(1 + mu^2)`` and tangential part
    ``mu`` times that. For ``mu > 1`` the formula is rewritten in ``1/mu`` so
    that huge coefficients neither overflow nor lose the tangential part. ``f_n == 0``
    with ``t != 0`` falls in the third case, which the original C++ got wrong.
    """
    fn = normal[0] * v[0] + normal[1] * v[1] + normal[2] * v[2]
    t0 = v[0] - fn * normal[0]
    t1 = v[1] - fn * normal[1]
    t2 = v[2] - fn * normal[2]
    a = math.sqrt(t0 * t0 + t1 * t1 + t2 * t2)
    if a <= mu * fn:
        out[0], out[1], out[2] = v[0], v[1], v[2]
    elif mu * a <= -fn:
        out[0], out[1], out[2] = 0.0, 0.0, 0.0
    else:
        if mu <= 1.0:
            normal_part = (mu * a + fn) / (1.0 + mu * mu)
            tangential_part = mu * normal_part
        else:
            inv = 1.0 / mu
            tangential_part = (a + fn * inv) / (1.0 + inv * inv)
            normal_part = tangential_part * inv
        scale = tangential_part / a
        out[0] = normal_part * normal[0] + scale * t0
        out[1] = normal_part * normal[1] + scale * t1
        out[2] = normal_part * normal[2] + scale * t2


@njit(cache=True)
def project_second_order_cone(v, out):
    """Project ``v = (t, w)`` onto ``{(t, w) : ||w|| <= t}`` into ``out``."""
    t = v[0]
    norm_w = 0.0
    for i in range(1, v.shape[0]):
        norm_w += v[i] * v[i]
    norm_w = math.sqrt(norm_w)
    if norm_w <= t:
        out[:] = v
    elif norm_w <= -t:
        out[:] = 0.0
    else:
        half = 0.5 * (t + norm_w)
        out[0] = half
        scale = half / norm_w
        for i in range(1, v.shape[0]):
            out[i] = scale * v[i]


@njit(cache=True)
def project_cone_block(v, kind, mu, normal, out):
    """Project one cone block, dispatching on its kind code."""
    if kind == FRICTION:
        project_friction_cone(v, mu, normal, out)
    else:
        project_second_order_cone(v, out)


@njit(cache=True)
def project_constraint_set(v, lo, hi, cones, out):
    """Project ``v`` onto the box ``[lo, hi]`` times the cones into ``out``.

    ``cones`` is the tuple ``(kind, offset, dim, mu, normal)`` of
    :class:`fccqp.cones.ConeArrays`; offsets index ``v``. ``out`` may be ``v``.
    """
    kind, offset, dim, mu, normal = cones
    for i in range(v.shape[0]):
        out[i] = min(max(v[i], lo[i]), hi[i])
    for c in range(kind.shape[0]):
        s, e = offset[c], offset[c] + dim[c]
        project_cone_block(v[s:e], kind[c], mu[c], normal[c], out[s:e])
