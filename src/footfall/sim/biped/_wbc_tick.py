"""Compiled packing of the biped's whole-body QP (numba, beyond the documents).

:func:`pack_tick` writes one physics step's contacts and tasks (:mod:`footfall.sim.biped.wbc`'s
module docstring) straight into the arrays of :class:`footfall.control.wbc.PackedProblem` and
assembles the QP (:func:`footfall.control._wbc_kernel.assemble`) in the same call: the same
numbers as building :class:`~footfall.control.wbc.Contact`, ``MotionTask`` and ``WrenchTask``
and packing them, without the ~100 small numpy operations and dataclasses per step that cost
more than the QP itself at 500 Hz. :func:`tally_step` is :class:`~footfall.sim.biped.wbc.WbcTally`
's account of one solution.

Same numbers, bit for bit: every sum that numpy left to BLAS (matrix-vector products, the 3 x 3
rotation products, dot products) is numba's ``np.dot``, which calls BLAS the same way; the
elementwise arithmetic is written in numpy's order (numba contracts no multiply-add into an FMA);
``(m z)^2`` is libm's ``pow`` as in Python (``math.pow`` with an exponent LLVM cannot see: its
``x * x`` differs from ``pow(x, 2)`` in the last bit about once in a thousand).

Everything compiled lives in this module (numba's on-disk cache, ``cache=True``, keys on it).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from footfall.control._wbc_kernel import assemble, rotation_error

#: entries of the gains vector of :func:`pack_tick`
(COM_KP, COM_KD, TORSO_KP, TORSO_KD, SWING_KP, SWING_KD, POSTURE_KP, POSTURE_KD) = range(8)
(MOMENTUM_KD, COP_SHARE, MASS, COM_W, COP_W, MOMENTUM_W, TORSO_W, SWING_W) = range(8, 16)
(POSTURE_W, SQUARE) = range(16, 18)
N_GAINS = 18
#: entries of the per-step vector of :func:`pack_tick`: the share of the control period, the
#: CoM (3) [m], its velocity (3) [m/s], the angular momentum about it (3), a CoP task (1) or
#: none (0), its point (3) [m] and horizontal moment (2) [N m]
SHARE, COM, VEL, L_G, HAS_COP, COP_POINT, COP_MOMENT = 0, 1, 4, 7, 10, 11, 14
N_STEP = 16
#: the reference keys of :func:`pack_tick`'s ``refs``: the CoM, then the soles in side order
REF_COM = 0
#: a corner carrying at least this normal force [N] counts in the friction share
LOADED_CORNER = 1.0


@njit(cache=True)
def _matvec(a: np.ndarray, x: np.ndarray, out: np.ndarray) -> None:
    """``out = a @ x`` for ``a`` (r, n), ``x`` (n,), ``out`` (r,): BLAS's product, as numpy's
    ``@`` (a loop sums in another order)."""
    out[:] = np.dot(a, x)


@njit(cache=True)
def pack_tick(
    step: np.ndarray,
    contact_sides: np.ndarray,
    cop_sides: np.ndarray,
    gains: np.ndarray,
    gravity: np.ndarray,
    refs: np.ndarray,
    yaw_rot: np.ndarray,
    rot_ref: np.ndarray,
    q_nominal: np.ndarray,
    sole_sites: np.ndarray,
    corner_geoms: np.ndarray,
    corner_radius: np.ndarray,
    side_friction: np.ndarray,
    torso: int,
    joint_qpos: np.ndarray,
    joint_dof: np.ndarray,
    qpos: np.ndarray,
    qvel: np.ndarray,
    qfrc_bias: np.ndarray,
    qfrc_passive: np.ndarray,
    site_xpos: np.ndarray,
    site_xmat: np.ndarray,
    geom_xpos: np.ndarray,
    xmat: np.ndarray,
    foot_jac: np.ndarray,
    foot_jdot: np.ndarray,
    torso_jac: np.ndarray,
    torso_jdot: np.ndarray,
    mass: np.ndarray,
    bias: np.ndarray,
    c_jac: np.ndarray,
    c_drift: np.ndarray,
    c_origin: np.ndarray,
    c_points: np.ndarray,
    c_normal: np.ndarray,
    c_friction: np.ndarray,
    m_jac: np.ndarray,
    m_rhs: np.ndarray,
    m_w: np.ndarray,
    w_rows: np.ndarray,
    w_about: np.ndarray,
    w_target: np.ndarray,
    w_weight: np.ndarray,
    w_mask: np.ndarray,
    actuated: np.ndarray,
    unactuated: np.ndarray,
    torque_min: np.ndarray,
    torque_max: np.ndarray,
    n_points: np.ndarray,
    tangent: np.ndarray,
    min_normal: np.ndarray,
    eps: tuple[float, float, float],
) -> tuple[
    int,
    int,
    int,
    tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, int, np.ndarray, bool],
]:
    """Fill one physics step's packed problem and assemble its QP: returns the numbers of
    contacts, motion rows and wrench rows (the leading parts of the arrays that count) and
    :func:`~footfall.control._wbc_kernel.assemble`'s QP.

    Inputs: ``step`` (N_STEP,) (the indices above); ``contact_sides`` (nc,) the sides in contact,
    in the contacts' order (0: the first of the walker's sides); ``cop_sides`` (2,) per side 1
    when its forces count in the CoP task; ``gains`` (N_GAINS,) (the indices above);
    ``gravity`` (3,) [m/s^2]; ``refs`` (3, 3, 3) per reference (the CoM, each sole) its position
    at the start and the end of the control period and its velocity; ``yaw_rot`` (3, 3) the
    torso's target; ``rot_ref`` (2, 3, 3) the soles' targets; ``q_nominal`` (nj,) the posture.
    The model: per side its sole site, corner geoms (4,) and their radii, the soles' friction;
    the torso body, the joints' qpos and dof indices (nj,). The MuJoCo state (``mj_step1`` or
    ``mj_forward`` has run): ``qpos``, ``qvel``, ``qfrc_bias``, ``qfrc_passive``, ``site_xpos``,
    ``site_xmat``, ``geom_xpos``, ``xmat``; the Jacobians of each sole centre ``foot_jac``,
    ``foot_jdot`` (2, 6, nv) and of the torso origin ``torso_jac``, ``torso_jdot`` (6, nv); ``M``
    in ``mass`` (nv, nv).

    Outputs (written in place): ``bias`` (nv,) ``h``; the contacts' ``c_jac`` (2, 6, nv),
    ``c_drift`` (2, 6), ``c_origin`` (2, 3), ``c_points`` (2, 4, 3), ``c_normal`` (2, 3),
    ``c_friction`` (2,); the motion rows ``m_jac`` (rm, nv), ``m_rhs``, ``m_w`` (rm,) (the
    torso's 3, each swing sole's 6, the posture's nj); the wrench rows ``w_rows`` (rw, 6),
    ``w_about`` (rw, 3), ``w_target``, ``w_weight`` (rw,), ``w_mask`` (rw, 2) (the CoP's 2, the
    CoM force's 3, the momentum's 3). Then the constant rest of the packed problem (actuated and
    other dofs, torque limits, per contact its point count, pyramid orientation (zero) and
    minimum normal force) and the controller's regularisation weights ``eps``.
    """
    nv = qvel.shape[0]
    nc = contact_sides.shape[0]
    g = gains
    share = step[SHARE]
    com = step[COM : COM + 3]
    vel = step[VEL : VEL + 3]
    drift = np.empty((2, 6))
    for sd in range(2):
        _matvec(foot_jdot[sd], qvel, drift[sd])
    for a in range(nv):
        bias[a] = qfrc_bias[a] - qfrc_passive[a]
    # --- contacts: each sole at the lowest points of its corner spheres, moved toward the centre
    lowest = math.inf
    for i in range(nc):
        sd = contact_sides[i]
        sid = sole_sites[sd]
        pos = site_xpos[sid]
        for j in range(3):
            c_normal[i, j] = site_xmat[sid, 2 + 3 * j]  # the sole's z axis
            c_origin[i, j] = pos[j]
        for k in range(4):
            gid = corner_geoms[sd, k]
            for j in range(3):
                corner = geom_xpos[gid, j] - corner_radius[sd, k] * c_normal[i, j]
                c_points[i, k, j] = pos[j] + g[COP_SHARE] * (corner - pos[j])
            if c_points[i, k, 2] < lowest:
                lowest = c_points[i, k, 2]
        c_jac[i] = foot_jac[sd]
        c_drift[i] = drift[sd]
        c_friction[i] = side_friction[sd]
    # --- wrench rows: the CoP, the CoM force (Newton), the centroidal momentum
    rw = 0
    w_mask[:] = 0.0
    has_cop = step[HAS_COP] != 0.0
    if has_cop:
        for r in range(2):
            w_rows[r] = 0.0
            w_rows[r, 3 + r] = 1.0
            for j in range(3):
                w_about[r, j] = step[COP_POINT + j]
            w_target[r] = step[COP_MOMENT + r]
            w_weight[r] = g[COP_W]
            for i in range(nc):
                if cop_sides[contact_sides[i]]:
                    w_mask[r, i] = 1.0
        rw = 2
    if nc > 0:
        ref = refs[REF_COM]
        for j in range(3):
            c_ref = ref[0, j] + share * (ref[1, j] - ref[0, j])
            a_com = g[COM_KP] * (c_ref - com[j]) + g[COM_KD] * (ref[2, j] - vel[j])
            r = rw + j
            w_rows[r] = 0.0
            w_rows[r, j] = 1.0
            w_about[r] = com
            w_target[r] = g[MASS] * (a_com - gravity[j])
            w_weight[r] = 0.0 if has_cop and j < 2 else g[COM_W]
            w_mask[r, :nc] = 1.0
        rw += 3
        z = com[2] - lowest
        z = z if z > 0.3 else 0.3
        weight = g[MOMENTUM_W] / math.pow(g[MASS] * z, g[SQUARE])
        for j in range(3):
            r = rw + j
            w_rows[r] = 0.0
            w_rows[r, 3 + j] = 1.0
            w_about[r] = com
            w_target[r] = -g[MOMENTUM_KD] * step[L_G + j]
            w_weight[r] = weight
            w_mask[r, :nc] = 1.0
        rw += 3
    # --- motion rows: the torso upright at the commanded yaw
    tdrift = np.empty(6)
    _matvec(torso_jdot, qvel, tdrift)
    omega = np.empty(3)
    _matvec(torso_jac.reshape(2, 3, nv)[1], qvel, omega)  # the angular rows, C-contiguous
    err = rotation_error(yaw_rot, xmat[torso].reshape(3, 3))
    for j in range(3):
        a = g[TORSO_KP] * err[j] - g[TORSO_KD] * omega[j]
        m_jac[j] = torso_jac[3 + j]
        m_rhs[j] = a - tdrift[3 + j]
        m_w[j] = g[TORSO_W]
    rm = 3
    # --- the swing soles
    v = np.empty(6)
    for sd in range(2):
        in_contact = False
        for i in range(nc):
            in_contact = in_contact or contact_sides[i] == sd
        if in_contact:
            continue
        sid = sole_sites[sd]
        pos = site_xpos[sid]
        _matvec(foot_jac[sd], qvel, v)
        ref = refs[1 + sd]
        err = rotation_error(rot_ref[sd], site_xmat[sid].reshape(3, 3))
        for j in range(3):
            pos_ref = ref[0, j] + share * (ref[1, j] - ref[0, j])
            a = g[SWING_KP] * (pos_ref - pos[j]) + g[SWING_KD] * (ref[2, j] - v[j])
            m_jac[rm + j] = foot_jac[sd, j]
            m_rhs[rm + j] = a - drift[sd, j]
            a = g[SWING_KP] * err[j] - g[SWING_KD] * v[3 + j]
            m_jac[rm + 3 + j] = foot_jac[sd, 3 + j]
            m_rhs[rm + 3 + j] = a - drift[sd, 3 + j]
        for j in range(6):
            m_w[rm + j] = g[SWING_W]
        rm += 6
    # --- the posture (no drift)
    for k in range(joint_dof.shape[0]):
        dof = joint_dof[k]
        a = g[POSTURE_KP] * (q_nominal[k] - qpos[joint_qpos[k]]) - g[POSTURE_KD] * qvel[dof]
        m_jac[rm] = 0.0
        m_jac[rm, dof] = 1.0
        m_rhs[rm] = a - 0.0
        m_w[rm] = g[POSTURE_W]
        rm += 1
    qp = assemble(
        mass,
        bias,
        actuated,
        unactuated,
        torque_min,
        torque_max,
        c_jac[:nc],
        c_drift[:nc],
        c_origin[:nc],
        c_points[:nc],
        n_points[:nc],
        c_normal[:nc],
        tangent[:nc],
        c_friction[:nc],
        min_normal[:nc],
        m_jac[:rm],
        m_rhs[:rm],
        m_w[:rm],
        w_rows[:rw],
        w_about[:rw],
        w_target[:rw],
        w_weight[:rw],
        w_mask[:rw, :nc],
        eps[0],
        eps[1],
        eps[2],
    )
    return nc, rm, rw, qp


@njit(cache=True)
def tally_step(
    x: np.ndarray,
    torque: np.ndarray,
    torque_limit: np.ndarray,
    nv: int,
    c_normal: np.ndarray,
    c_friction: np.ndarray,
    stats: np.ndarray,
) -> None:
    """One solution's account (:meth:`footfall.sim.biped.wbc.WbcTally.add`, operation for
    operation) into ``stats`` (4,): the largest torque share, friction share and friction excess
    [N], the smallest corner normal force [N]. ``x`` (n,) the QP's solution, ``torque`` (na,),
    ``torque_limit`` (na,) > 0 (inf: none); per contact (nc, as ``c_normal`` (nc, 3) and
    ``c_friction`` (nc,)) four corner forces after the ``nv`` accelerations."""
    share = 0.0
    for k in range(torque.shape[0]):
        s = abs(torque[k]) / torque_limit[k]
        if s > share or math.isnan(s):
            share = s
    if share > stats[0]:
        stats[0] = share
    fn = np.empty(4)
    for i in range(c_normal.shape[0]):
        o = nv + 12 * i
        f = x[o : o + 12].reshape(4, 3)
        _matvec(f, c_normal[i], fn)
        fn_min = math.inf
        excess = -math.inf
        ratio_max = -math.inf
        for k in range(4):
            # numpy's einsum("ij,ij->i") on 3 columns: its 4-lane sum, (0 + 2) + 1
            sq = (f[k, 0] * f[k, 0] + f[k, 2] * f[k, 2]) + f[k, 1] * f[k, 1]
            t = sq - fn[k] * fn[k]
            ft = math.sqrt(t if t > 0.0 else 0.0)
            mu_fn = c_friction[i] * fn[k]
            fn_min = min(fn_min, fn[k])
            excess = max(excess, ft - mu_fn)
            den = mu_fn if mu_fn > 1e-12 else 1e-12
            ratio = ft / den if fn[k] > LOADED_CORNER else 0.0
            ratio_max = max(ratio_max, ratio)
        if fn_min < stats[3]:
            stats[3] = fn_min
        if excess > stats[2]:
            stats[2] = excess
        if ratio_max > stats[1]:
            stats[1] = ratio_max
