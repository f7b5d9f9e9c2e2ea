"""Compiled assembly of the whole-body QP of :mod:`footfall.control.wbc` (numba).

:func:`assemble` turns the packed arrays of one tick's problem into the dense QP that ``daqp``
solves, ``min 0.5 x^T H x + g^T x`` s.t. ``lower <= C x <= upper`` (equality rows first), with
``x = (qdd, f)``. It is the same algebra as the module docstring of :mod:`footfall.control.wbc`,
written as loops so that a 500 Hz controller does not spend its time in numpy's per-call overhead
(the numpy version took 0.3-0.5 ms per tick for a biped; this takes a few tens of microseconds).
:func:`rotation_error` is the orientation error both robots' trunk tasks track,
:func:`footfall._geometry.rotation_log` compiled (BLAS's 3 x 3 product through ``np.dot``, as
numpy's ``@``).

Everything compiled lives in this module (numba's on-disk cache, ``cache=True``, keys on it).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

#: daqp's stand-in for an infinite bound
INFINITY = 1e30
#: the inscribed friction pyramid: each tangential component at most mu / sqrt(2) of the normal
PYRAMID_SHARE = 0.7071067811865476


@njit(cache=True)
def _tangents(n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit tangents orthogonal to the unit normal ``n`` (3,) and to each other."""
    t1 = np.empty(3)
    if abs(n[0]) < 0.9:  # n x e_x
        t1[0], t1[1], t1[2] = 0.0, n[2], -n[1]
    else:  # n x e_y
        t1[0], t1[1], t1[2] = -n[2], 0.0, n[0]
    t1 /= np.sqrt(t1[0] ** 2 + t1[1] ** 2 + t1[2] ** 2)
    t2 = np.empty(3)
    t2[0] = n[1] * t1[2] - n[2] * t1[1]
    t2[1] = n[2] * t1[0] - n[0] * t1[2]
    t2[2] = n[0] * t1[1] - n[1] * t1[0]
    return t1, t2


@njit(cache=True)
def rotation_log(r: np.ndarray) -> np.ndarray:
    """:func:`footfall._geometry.rotation_log` compiled, operation for operation."""
    w = np.empty(3)
    w[0] = r[2, 1] - r[1, 2]
    w[1] = r[0, 2] - r[2, 0]
    w[2] = r[1, 0] - r[0, 1]
    s = 0.5 * math.sqrt(np.dot(w, w))
    c = 0.5 * ((r[0, 0] + r[1, 1] + r[2, 2]) - 1.0)
    angle = math.atan2(s, c)
    if angle < 1e-9:
        return 0.5 * w
    if c > -0.9:
        return (angle / (2.0 * s)) * w
    b = (0.5 * (r + r.T) - c * np.eye(3)) / (1.0 - c)
    k = int(np.argmax(np.diag(b)))
    bkk = b[k, k]
    axis = b[:, k] / math.sqrt(1e-300 if 1e-300 > bkk else bkk)
    axis = axis / math.sqrt(np.dot(axis, axis))
    if np.dot(axis, w) < 0.0:
        axis = -axis
    return angle * axis


@njit(cache=True)
def rotation_error(target: np.ndarray, actual: np.ndarray) -> np.ndarray:
    """Rotation vector (3,) [rad] that turns ``actual`` (3, 3) into ``target`` (3, 3)."""
    return rotation_log(np.dot(target, actual.T))


@njit(cache=True)
def assemble(
    mass: np.ndarray,
    bias: np.ndarray,
    actuated: np.ndarray,
    unactuated: np.ndarray,
    torque_min: np.ndarray,
    torque_max: np.ndarray,
    jac: np.ndarray,
    drift: np.ndarray,
    origin: np.ndarray,
    points: np.ndarray,
    n_points: np.ndarray,
    normal: np.ndarray,
    tangent: np.ndarray,
    friction: np.ndarray,
    min_normal: np.ndarray,
    motion_jac: np.ndarray,
    motion_rhs: np.ndarray,
    motion_w: np.ndarray,
    wrench_rows: np.ndarray,
    wrench_about: np.ndarray,
    wrench_target: np.ndarray,
    wrench_w: np.ndarray,
    wrench_mask: np.ndarray,
    eps_qacc: float,
    eps_force: float,
    eps_torque: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, int, np.ndarray, bool]:
    """The QP of one tick.

    Shapes: ``mass`` (nv, nv), ``bias`` (nv,), ``actuated`` (na,), ``unactuated`` (nu,);
    per contact c < nc: ``jac`` (nc, 6, nv), ``drift`` (nc, 6), ``origin`` (nc, 3), ``points``
    (nc, kmax, 3) of which the first ``n_points[c]`` count, ``normal`` (nc, 3), ``tangent``
    (nc, 3) (the first face direction of the friction pyramid; zero: any), ``friction`` and
    ``min_normal`` (nc,); motion rows ``motion_jac`` (rm, nv), ``motion_rhs`` (rm,) (the desired
    acceleration minus the drift), ``motion_w`` (rm,); wrench rows ``wrench_rows`` (rw, 6),
    ``wrench_about`` (rw, 3), ``wrench_target`` (rw,), ``wrench_w`` (rw,), ``wrench_mask``
    (rw, nc) (1: contact c's forces count).

    Returns ``(H, g, C, lower, upper, n_eq, T, zero_row_value)`` where ``T`` (na, n + 1) maps
    ``(x, 1)`` to the joint torques: ``tau = T[:, :n] x + T[:, n]``. Equality rows that are zero
    (a point contact's angular rows, 0 = 0) are left out of ``C`` and ``n_eq``: they would make
    the active set's system singular; ``zero_row_value`` is True when such a row has a non-zero
    value (an infeasible problem).
    """
    nv = mass.shape[0]
    nc = jac.shape[0]
    na = actuated.shape[0]
    nu = unactuated.shape[0]
    offset = np.zeros(nc + 1, dtype=np.int64)
    for c in range(nc):
        offset[c + 1] = offset[c] + 3 * n_points[c]
    nf = offset[nc]
    n = nv + nf
    # dyn x = M qdd - Jc^T f, where the force f_i at p_i = o_c + r on body c adds
    # J_lin^T f_i + J_ang^T (r x f_i) to the generalised force
    dyn = np.zeros((nv, n))
    dyn[:, :nv] = mass
    for c in range(nc):
        for i in range(n_points[c]):
            rx = points[c, i, 0] - origin[c, 0]
            ry = points[c, i, 1] - origin[c, 1]
            rz = points[c, i, 2] - origin[c, 2]
            col = nv + offset[c] + 3 * i
            for a in range(nv):
                # coefficient of f_j: J_lin[j, a] - (r x w)_j with w = J_ang[:, a]
                wx, wy, wz = jac[c, 3, a], jac[c, 4, a], jac[c, 5, a]
                dyn[a, col] = -(jac[c, 0, a] - (ry * wz - rz * wy))
                dyn[a, col + 1] = -(jac[c, 1, a] - (rz * wx - rx * wz))
                dyn[a, col + 2] = -(jac[c, 2, a] - (rx * wy - ry * wx))
    # --- least squares: rows A, targets b, weights w
    rm = motion_jac.shape[0]
    rw = wrench_rows.shape[0]
    r_all = rm + rw + na
    a_ls = np.zeros((r_all, n))
    b_ls = np.zeros(r_all)
    w_ls = np.zeros(r_all)
    for r in range(rm):
        a_ls[r, :nv] = motion_jac[r]
        b_ls[r] = motion_rhs[r]
        w_ls[r] = motion_w[r]
    for r in range(rw):
        row = rm + r
        b_ls[row] = wrench_target[r]
        w_ls[row] = wrench_w[r]
        fr = wrench_rows[r, :3]
        mr = wrench_rows[r, 3:]
        for c in range(nc):
            if wrench_mask[r, c] == 0.0:
                continue
            for i in range(n_points[c]):
                # R_f . f + R_m . ((p - about) x f) = (R_f + R_m x (p - about)) . f
                qx = points[c, i, 0] - wrench_about[r, 0]
                qy = points[c, i, 1] - wrench_about[r, 1]
                qz = points[c, i, 2] - wrench_about[r, 2]
                col = nv + offset[c] + 3 * i
                a_ls[row, col] = fr[0] + mr[1] * qz - mr[2] * qy
                a_ls[row, col + 1] = fr[1] + mr[2] * qx - mr[0] * qz
                a_ls[row, col + 2] = fr[2] + mr[0] * qy - mr[1] * qx
    t_map = np.zeros((na, n + 1))
    for k in range(na):
        t_map[k, :n] = dyn[actuated[k]]
        t_map[k, n] = bias[actuated[k]]
        row = rm + rw + k
        a_ls[row] = dyn[actuated[k]]
        b_ls[row] = -bias[actuated[k]]
        w_ls[row] = eps_torque
    aw = a_ls * w_ls.reshape(-1, 1)
    h_mat = a_ls.T @ aw
    g_vec = -(aw.T @ b_ls)
    for j in range(nv):
        h_mat[j, j] += eps_qacc
    for j in range(nv, n):
        h_mat[j, j] += eps_force
    # --- constraints: equalities (floating base, contact accelerations), then inequalities
    n_eq = nu + 6 * nc
    m_rows = n_eq + na + 5 * (nf // 3)
    c_mat = np.zeros((m_rows, n))
    lower = np.empty(m_rows)
    upper = np.empty(m_rows)
    row = 0
    for k in range(nu):
        c_mat[row] = dyn[unactuated[k]]
        lower[row] = upper[row] = -bias[unactuated[k]]
        row += 1
    for c in range(nc):
        for j in range(6):
            c_mat[row, :nv] = jac[c, j]
            lower[row] = upper[row] = -drift[c, j]
            row += 1
    for k in range(na):
        c_mat[row] = dyn[actuated[k]]
        lower[row] = max(torque_min[k] - bias[actuated[k]], -INFINITY)
        upper[row] = min(torque_max[k] - bias[actuated[k]], INFINITY)
        row += 1
    for c in range(nc):
        nrm = normal[c]
        t1, t2 = _tangents(nrm)
        if tangent[c, 0] != 0.0 or tangent[c, 1] != 0.0 or tangent[c, 2] != 0.0:
            t1 = tangent[c].copy()
            t2[0] = nrm[1] * t1[2] - nrm[2] * t1[1]
            t2[1] = nrm[2] * t1[0] - nrm[0] * t1[2]
            t2[2] = nrm[0] * t1[1] - nrm[1] * t1[0]
        mu = friction[c] * PYRAMID_SHARE
        for i in range(n_points[c]):
            col = nv + offset[c] + 3 * i
            for j in range(3):
                c_mat[row, col + j] = nrm[j]
                c_mat[row + 1, col + j] = t1[j] - mu * nrm[j]
                c_mat[row + 2, col + j] = -t1[j] - mu * nrm[j]
                c_mat[row + 3, col + j] = t2[j] - mu * nrm[j]
                c_mat[row + 4, col + j] = -t2[j] - mu * nrm[j]
            lower[row], upper[row] = min_normal[c], INFINITY
            for j in range(1, 5):
                lower[row + j], upper[row + j] = -INFINITY, 0.0
            row += 5
    # drop the zero equality rows, moving the rows after them up in place
    kept = 0
    kept_eq = n_eq
    zero_row_value = False
    for r in range(m_rows):
        if r < n_eq:
            zero = True
            for j in range(n):
                if c_mat[r, j] != 0.0:
                    zero = False
                    break
            if zero:
                zero_row_value = zero_row_value or lower[r] != 0.0
                kept_eq -= 1
                continue
        if kept != r:
            c_mat[kept] = c_mat[r]
            lower[kept] = lower[r]
            upper[kept] = upper[r]
        kept += 1
    return (
        h_mat,
        g_vec,
        c_mat[:kept],
        lower[:kept],
        upper[:kept],
        kept_eq,
        t_map,
        zero_row_value,
    )
