"""Compiled measurement of one control sample of the quadruped's walk (numba, beyond the documents).

:func:`foot_contacts` reads the feet's contact points and forces out of MuJoCo's contact arrays
(``mj_contactForce``'s numbers without a call per contact); :func:`measure_sample` is
:meth:`footfall.sim.quadruped.sim._Recorder.measure`'s arithmetic: the loaded feet, the centre
of pressure (:func:`~footfall.quadruped.stability.centre_of_pressure`), the stability margin in
their support polygon (:func:`~footfall.quadruped.stability.stability_margin` of
:func:`~footfall.quadruped.stability.support_polygon`) and each foot's sliding velocity. Written
in Python and numpy they cost ~0.3 ms per sample, more than the physics of the sample.

Same numbers, bit for bit, as the Python and numpy code: numpy's sums are its pairwise summation
(:func:`_sum`), its dot products and ``@`` are BLAS's through numba's ``np.dot`` (``0.0 +`` the
product, as numpy adds BLAS's ``ddot`` to a zero), the elementwise and Python-float arithmetic
is written in the same order (numba contracts no multiply-add into an FMA), the hull sorts its
points as Python sorts tuples (stably, x then y).

Everything compiled lives in this module (numba's on-disk cache, ``cache=True``, keys on it).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

#: numpy's pairwise summation: blocks of this many elements are summed with 8 accumulators
_PAIRWISE_BLOCK = 128


@njit(cache=True)
def _block(a: np.ndarray, lo: int, n: int) -> float:
    """numpy's ``pairwise_sum`` of ``a[lo:lo + n]`` (1-D) for ``n`` up to its block size: in
    order below 8 elements, else with 8 accumulators."""
    if n < 8:
        res = -0.0
        for i in range(lo, lo + n):
            res += a[i]
        return res
    r = a[lo : lo + 8].copy()
    i = 8
    while i < n - n % 8:
        for j in range(8):
            r[j] += a[lo + i + j]
        i += 8
    res = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]))
    while i < n:
        res += a[lo + i]
        i += 1
    return res


@njit(cache=True)
def _sum(a: np.ndarray) -> float:
    """``a.sum()`` of a 1-D float array as numpy computes it: its identity 0.0 plus the pairwise
    sum, which halves a longer array (at a multiple of 8) until the parts fit a block. The halving
    runs on explicit stacks (numba's cache breaks recursive functions)."""
    # pending parts (first element, length, 1 = add the two results above) and results
    lo, n, join = np.empty(192, np.int64), np.empty(192, np.int64), np.empty(192, np.bool_)
    results = np.empty(64)
    lo[0], n[0], join[0] = 0, a.shape[0], False
    top, done = 1, 0
    while top > 0:
        top -= 1
        if join[top]:
            results[done - 2] = results[done - 2] + results[done - 1]
            done -= 1
        elif n[top] <= _PAIRWISE_BLOCK:
            results[done] = _block(a, lo[top], n[top])
            done += 1
        else:
            start, m = lo[top], n[top]
            half = m // 2
            half -= half % 8
            # popped in reverse order: the first half, the second, then their sum
            lo[top], n[top], join[top] = start, m, True
            lo[top + 1], n[top + 1], join[top + 1] = start + half, m - half, False
            lo[top + 2], n[top + 2], join[top + 2] = start, half, False
            top += 3
    return 0.0 + results[0]


@njit(cache=True)
def _dot(a: np.ndarray, b: np.ndarray) -> float:
    """``a @ b`` of two 1-D float arrays as numpy computes it: 0.0 plus BLAS's ``ddot``."""
    return 0.0 + np.dot(a, b)


@njit(cache=True)
def foot_contacts(
    geom: np.ndarray,
    pos: np.ndarray,
    frame: np.ndarray,
    efc_address: np.ndarray,
    dim: np.ndarray,
    friction: np.ndarray,
    efc_force: np.ndarray,
    pyramidal: bool,
    foot_of_geom: np.ndarray,
    trunk_geom: int,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, bool]:
    """:meth:`footfall.sim.quadruped.sim.QuadrupedSim.contacts` from MuJoCo's contact arrays.

    Inputs (``d.contact``'s fields for its ``ncon`` contacts): ``geom`` (ncon, 2), ``pos``
    (ncon, 3) [m], ``frame`` (ncon, 9) (rows normal, tangent 1, tangent 2), ``efc_address``
    (ncon,) (< 0: no constraint rows), ``dim`` (ncon,), ``friction`` (ncon, 5); ``d.efc_force``;
    ``pyramidal`` whether the model's friction cone is pyramidal (else elliptic);
    ``foot_of_geom`` (ngeom,) each geom's leg or -1; ``trunk_geom`` the trunk's geom.

    Returns ``(points (N, 3) [m], forces on the robot (N, 3) [N] in {W}, foot index (N,),
    trunk_touches_ground)``. The force in the contact frame is ``mj_contactForce``'s: the
    constraint force as is (elliptic cone) or decoded from the pyramid's edges.
    """
    n = geom.shape[0]
    pts = np.empty((n, 3))
    frc = np.empty((n, 3))
    idx = np.empty(n, dtype=np.int64)
    local = np.empty(3)
    rot = np.empty((3, 3))
    found = 0
    trunk_hit = False
    for i in range(n):
        g1, g2 = geom[i, 0], geom[i, 1]
        if g1 == trunk_geom or g2 == trunk_geom:
            trunk_hit = True
            continue
        if g1 >= 0 and foot_of_geom[g1] >= 0:
            foot, sign = foot_of_geom[g1], -1.0
        elif g2 >= 0 and foot_of_geom[g2] >= 0:
            foot, sign = foot_of_geom[g2], 1.0
        else:
            continue
        # mj_contactForce: zero without constraint rows; the pyramid's 2 (dim - 1) edge forces
        # sum to the normal force, opposite edges differ by the tangential ones over mu
        local[:] = 0.0
        adr, nd = efc_address[i], dim[i]
        if adr >= 0:
            if not pyramidal or nd == 1:
                for r in range(min(nd, 3)):
                    local[r] = efc_force[adr + r]
            else:
                normal = 0.0
                for r in range(2 * (nd - 1)):
                    normal += efc_force[adr + r]
                local[0] = normal
                for r in range(min(nd - 1, 2)):
                    local[r + 1] = (efc_force[adr + 2 * r] - efc_force[adr + 2 * r + 1]) * friction[
                        i, r
                    ]
        # the force acts from geom1 on geom2: on the robot as is when the foot is geom2
        for r in range(3):
            for c in range(3):
                rot[r, c] = frame[i, 3 * r + c]
        world = np.dot(rot.T, local)
        for r in range(3):
            pts[found, r] = pos[i, r]
            frc[found, r] = sign * world[r]
        idx[found] = foot
        found += 1
    return pts[:found], frc[:found], idx[:found], trunk_hit


@njit(cache=True)
def _turn(o: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


@njit(cache=True)
def _chain(points: np.ndarray, eps: float) -> np.ndarray:
    """:func:`footfall._geometry.monotone_chain` of ``points`` (M >= 1, 2) [m], shape (K, 2)."""
    m = points.shape[0]
    xy = points.copy()
    # insertion sort, stable, comparing (x, y) as Python compares tuples
    for i in range(1, m):
        x, y = xy[i, 0], xy[i, 1]
        j = i - 1
        while j >= 0 and (x < xy[j, 0] or (x == xy[j, 0] and y < xy[j, 1])):
            xy[j + 1] = xy[j]
            j -= 1
        xy[j + 1, 0], xy[j + 1, 1] = x, y
    keep = np.empty((m, 2))
    keep[0] = xy[0]
    k = 1
    for i in range(1, m):
        if abs(xy[i, 0] - xy[i - 1, 0]) > eps or abs(xy[i, 1] - xy[i - 1, 1]) > eps:
            keep[k] = xy[i]
            k += 1
    if k <= 2:
        return keep[:k]
    lower = np.empty((k, 2))
    nl = 0
    for i in range(k):
        while nl >= 2 and _turn(lower[nl - 2], lower[nl - 1], keep[i]) <= eps:
            nl -= 1
        lower[nl] = keep[i]
        nl += 1
    upper = np.empty((k, 2))
    nu = 0
    for i in range(k - 1, -1, -1):
        while nu >= 2 and _turn(upper[nu - 2], upper[nu - 1], keep[i]) <= eps:
            nu -= 1
        upper[nu] = keep[i]
        nu += 1
    if nl - 1 + nu - 1 < 2:
        out = np.empty((2, 2))
        out[0], out[1] = keep[0], keep[k - 1]
        return out
    out = np.empty((nl - 1 + nu - 1, 2))
    out[: nl - 1] = lower[: nl - 1]
    out[nl - 1 :] = upper[: nu - 1]
    return out


@njit(cache=True)
def _segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray, eps: float) -> float:
    """``footfall.quadruped.stability._point_segment_distance``: distance of ``p`` (2,) from the
    segment ``a``-``b`` [m]."""
    ab = b - a
    denom = _dot(ab, ab)
    t = 0.0
    if not denom <= eps:
        u = _dot(p - a, ab) / denom
        # np.clip(u, 0, 1): NaN stays NaN
        if not math.isnan(u):
            u = u if u > 0.0 else 0.0
            u = u if u < 1.0 else 1.0
        t = u
    e = p - (a + t * ab)
    return math.sqrt(_dot(e, e))


@njit(cache=True)
def _margin(p: np.ndarray, points: np.ndarray, eps: float) -> float:
    """``stability_margin(p, support_polygon(points))`` [m] of ``p`` (2,) and ``points`` (M, 3)."""
    poly = _chain(_chain(np.ascontiguousarray(points[:, :2]), eps), eps)
    k = poly.shape[0]
    if k == 1:
        e = p - poly[0]
        return -math.sqrt(_dot(e, e))
    if k == 2:
        return -_segment_distance(p, poly[0], poly[1], eps)
    px, py = p[0], p[1]
    least = math.inf
    for i in range(k):
        ax, ay = poly[i, 0], poly[i, 1]
        bx, by = poly[(i + 1) % k, 0], poly[(i + 1) % k, 1]
        ex, ey = bx - ax, by - ay
        length = math.sqrt(ex * ex + ey * ey)
        # CCW polygon: the inward normal of edge (a -> b) is the edge rotated by +90 degrees
        signed = (px - ax) * (-ey / length) + (py - ay) * (ex / length)
        if i == 0 or signed < least:
            least = signed
    if least >= 0.0:
        return least
    nearest = math.inf
    for i in range(k):
        dist = _segment_distance(p, poly[i], poly[(i + 1) % k], eps)
        if i == 0 or dist < nearest:
            nearest = dist
    return -nearest


@njit(cache=True)
def _sliding(
    vel: np.ndarray, point: np.ndarray, centre: np.ndarray, normal: np.ndarray, out: np.ndarray
) -> None:
    """The velocity [m/s] along the ground (unit ``normal`` (3,)) of the foot's material point at
    ``point`` (3,) into ``out`` (3,), from the foot geom's world-frame ``[angular, linear]``
    velocity ``vel`` (6,) at its centre ``centre`` (3,) [m]."""
    r = point - centre
    vp = np.empty(3)
    vp[0] = vel[3] + (vel[1] * r[2] - vel[2] * r[1])
    vp[1] = vel[4] + (vel[2] * r[0] - vel[0] * r[2])
    vp[2] = vel[5] + (vel[0] * r[1] - vel[1] * r[0])
    along = _dot(vp, normal)
    for i in range(3):
        out[i] = vp[i] - along * normal[i]


@njit(cache=True)
def measure_sample(
    k: int,
    pts: np.ndarray,
    frc: np.ndarray,
    idx: np.ndarray,
    loaded_force: float,
    eps: float,
    stance: np.ndarray,
    feet: np.ndarray,
    geom_xpos: np.ndarray,
    foot_geoms: np.ndarray,
    foot_vel: np.ndarray,
    normals: np.ndarray,
    cop: np.ndarray,
    margin: np.ndarray,
    n_contacts: np.ndarray,
    slip_vel: np.ndarray,
) -> None:
    """Sample ``k`` of the trace's measured contact quantities, written into its arrays.

    Inputs: the feet's contacts ``pts``, ``frc`` (N, 3), ``idx`` (N,) (:func:`foot_contacts`);
    ``loaded_force`` [N], the normal force above which a contact counts; ``eps`` [m] the hull's
    tolerance; ``stance`` (4,) the planned contacts; ``feet`` (4, 3) the foot centres [m] (sites);
    ``geom_xpos`` (ngeom, 3) [m] and ``foot_geoms`` (4,) the feet's geoms, ``foot_vel`` (4, 6) their
    ``[angular, linear]`` velocities (``mj_objectVelocity``, world frame); ``normals`` (N + 4, 3)
    the ground's normal at each contact point, then under each foot centre.

    Outputs (row ``k``): ``cop`` (T, 2) [m] and ``margin`` (T,) [m] of the loaded contacts (left
    as they are without one), ``n_contacts`` (T,) the feet loaded, ``slip_vel`` (T, 4, 3) [m/s]
    at each contact, and of a planned stance foot off the ground at its centre.
    """
    n = idx.shape[0]
    loaded = np.empty(n, dtype=np.int64)
    nl = 0
    seen = np.zeros(4, dtype=np.bool_)
    for j in range(n):
        if frc[j, 2] > loaded_force:
            loaded[nl] = j
            nl += 1
            seen[idx[j]] = True
    n_contacts[k] = seen.sum()
    if nl > 0:
        lp, lf = pts[loaded[:nl]], frc[loaded[:nl]]
        z_p = _sum(lp[:, 2].copy()) / nl
        # centre_of_pressure: the loaded forces push up (f_z > 0 each), so their sum is positive
        fz = _sum(lf[:, 2].copy())
        dz = lp[:, 2] - z_p
        cop[k, 0] = _sum(lp[:, 0] * lf[:, 2] - dz * lf[:, 0]) / fz
        cop[k, 1] = _sum(lp[:, 1] * lf[:, 2] - dz * lf[:, 1]) / fz
        margin[k] = _margin(cop[k], lp, eps)
    feet_sliding(pts, idx, stance, feet, geom_xpos, foot_geoms, foot_vel, normals, slip_vel[k])


@njit(cache=True)
def feet_sliding(
    pts: np.ndarray,
    idx: np.ndarray,
    stance: np.ndarray,
    feet: np.ndarray,
    geom_xpos: np.ndarray,
    foot_geoms: np.ndarray,
    foot_vel: np.ndarray,
    normals: np.ndarray,
    out: np.ndarray,
) -> None:
    """Each foot's sliding velocity [m/s] into ``out`` (4, 3): at each of its contacts (the last
    one written wins; a point foot has one), at its centre when it is planned in stance
    (``stance`` (4,)) but off the ground, zero otherwise. Inputs as :func:`measure_sample`'s."""
    n = idx.shape[0]
    out[:] = 0.0
    for j in range(n):
        leg = idx[j]
        _sliding(foot_vel[leg], pts[j], geom_xpos[foot_geoms[leg]], normals[j], out[leg])
    # a planned stance foot off the ground moves with its whole centre: that motion along the
    # ground is slip too
    for leg in range(4):
        if stance[leg] and not np.any(idx == leg):
            centre = geom_xpos[foot_geoms[leg]]
            _sliding(foot_vel[leg], feet[leg], centre, normals[n + leg], out[leg])


@njit(cache=True)
def _point_velocity(
    cvel: np.ndarray, subtree_com: np.ndarray, body: int, root: int, p: np.ndarray, out: np.ndarray
) -> None:
    """World-frame velocity [m/s] into ``out`` (3,) of the point ``p`` (3,) [m] fixed to
    ``body``: MuJoCo's com-based velocity ``cvel[body]`` (``[angular, linear]``, the linear part
    that of the point at ``subtree_com[root]``, ``root`` the body's tree root) moved to ``p``
    (``mj_objectVelocity``'s transform, world frame)."""
    w = cvel[body]
    rx = p[0] - subtree_com[root, 0]
    ry = p[1] - subtree_com[root, 1]
    rz = p[2] - subtree_com[root, 2]
    out[0] = w[3] + (w[1] * rz - w[2] * ry)
    out[1] = w[4] + (w[2] * rx - w[0] * rz)
    out[2] = w[5] + (w[0] * ry - w[1] * rx)


@njit(cache=True)
def slide_step(
    geom: np.ndarray,
    pos: np.ndarray,
    cvel: np.ndarray,
    subtree_com: np.ndarray,
    foot_body: np.ndarray,
    foot_root: np.ndarray,
    foot_of_geom: np.ndarray,
    trunk_geom: int,
    stance: np.ndarray,
    site_xpos: np.ndarray,
    foot_sites: np.ndarray,
    normals: np.ndarray,
    h: float,
    disp: np.ndarray,
) -> None:
    """Add one physics step's sliding of the four feet to ``disp`` (4, 3) [m]: each foot's
    velocity along the ground at its contact point (the last of its contacts wins, as in
    :func:`feet_sliding`), or at its site when it is planned in stance (``stance`` (4,)) but
    touches nothing, times the step ``h`` [s].

    Inputs: ``d.contact``'s ``geom`` (ncon, 2) and ``pos`` (ncon, 3) [m]; ``d.cvel`` (nbody, 6)
    and ``d.subtree_com`` (nbody, 3) [m]; ``foot_body`` (4,) each foot geom's body,
    ``foot_root`` (4,) that body's tree root; ``foot_of_geom`` (ngeom,) each geom's leg or -1,
    ``trunk_geom`` the trunk's geom (its contacts are no foot's); ``d.site_xpos`` (nsite, 3) [m] and ``foot_sites`` (4,);
    ``normals`` (4, 3) the ground's unit normal under each foot."""
    vel = np.empty(3)
    slide = np.zeros((4, 3))
    touched = np.zeros(4, dtype=np.bool_)
    for i in range(geom.shape[0]):
        g1, g2 = geom[i, 0], geom[i, 1]
        if g1 == trunk_geom or g2 == trunk_geom:
            continue
        if g1 >= 0 and foot_of_geom[g1] >= 0:
            foot = foot_of_geom[g1]
        elif g2 >= 0 and foot_of_geom[g2] >= 0:
            foot = foot_of_geom[g2]
        else:
            continue
        _point_velocity(cvel, subtree_com, foot_body[foot], foot_root[foot], pos[i], vel)
        along = _dot(vel, normals[foot])
        for r in range(3):
            slide[foot, r] = vel[r] - along * normals[foot, r]
        touched[foot] = True
    for leg in range(4):
        if stance[leg] and not touched[leg]:
            site = site_xpos[foot_sites[leg]]
            _point_velocity(cvel, subtree_com, foot_body[leg], foot_root[leg], site, vel)
            along = _dot(vel, normals[leg])
            for r in range(3):
                slide[leg, r] = vel[r] - along * normals[leg, r]
    for leg in range(4):
        for r in range(3):
            disp[leg, r] += slide[leg, r] * h
