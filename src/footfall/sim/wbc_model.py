"""The arrays of :mod:`footfall.control.wbc` filled from a MuJoCo model (any floating-base robot).

:class:`MujocoWbcModel` reads, at the state in ``MjData`` (after ``mj_forward``):

- the joint-space inertia ``M`` (``mj_fullM``, armature included) and ``h = qfrc_bias -
  qfrc_passive`` (Coriolis, centrifugal, gravity; joint damping and springs moved to the left), so
  that MuJoCo's ``M qacc + qfrc_bias = qfrc_passive + qfrc_actuator + qfrc_constraint`` reads
  ``M qdd + h = S^T tau + Jc^T f``;
- frame Jacobians at a point of a body (``mj_jac``) and their drift ``Jdot qd``
  (``mj_jacDot``);
- the torque limits of the actuators (``actuator_forcerange`` where force-limited, else the
  joint's ``jnt_actfrcrange``, else unbounded).

With ``implicit_damping`` it adds ``h D`` to ``M``: MuJoCo's implicit integrators apply the
joint damping at the end of the step, so ``(M + h D) qacc + h = S^T tau + Jc^T f`` is the
acceleration the step realizes.

:meth:`MujocoWbcModel.set_torque_mode` turns position servos into plain motors (gain 1, no
bias) so that ``ctrl`` is the joint torque; the force range still clips it.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from footfall._typing import FloatArray
from footfall.control.wbc import Contact
from footfall.errors import InputError


class MujocoWbcModel:
    """Model terms of :mod:`footfall.control.wbc` from MuJoCo.

    Args:
        mujoco: the ``mujoco`` module.
        model, data: ``MjModel`` and ``MjData``.
        actuators: (na,) actuator ids, each driving one hinge or slide joint directly
            (transmission ``joint``, gear 1).
        implicit_damping: with MuJoCo's implicit integrators (``implicit``, ``implicitfast``),
            add ``h D`` (time step times each dof's damping) to ``M``: those integrators take
            the damping force at the end of the step, ``(M + h D) qacc = f``, so a QP that
            assumes ``M`` alone gets less acceleration than it asked for (on the quadrupeds
            about 5 % at a swinging knee, so the feet ran 0.3-0.7 mm off their plan and
            touched down early with impact).
    """

    def __init__(
        self,
        mujoco: Any,
        model: Any,
        data: Any,
        actuators: FloatArray,
        implicit_damping: bool = False,
    ) -> None:
        self.mj, self.m, self.d = mujoco, model, data
        m = model
        self.actuators = np.asarray(actuators, dtype=int)
        trn = mujoco.mjtTrn.mjTRN_JOINT
        joints = []
        for a in self.actuators:
            if int(m.actuator_trntype[a]) != int(trn) or abs(m.actuator_gear[a, 0] - 1.0) > 1e-12:
                raise InputError("actuators", int(a), "actuators on a joint with gear 1")
            joints.append(int(m.actuator_trnid[a, 0]))
        self.joints = np.array(joints)
        #: (na,) degrees of freedom the actuators drive, in actuator order
        self.actuated = np.array([int(m.jnt_dofadr[j]) for j in self.joints])
        lo = np.full(len(joints), -np.inf)
        hi = np.full(len(joints), np.inf)
        for i, (a, j) in enumerate(zip(self.actuators, self.joints, strict=True)):
            if m.actuator_forcelimited[a]:
                lo[i], hi[i] = m.actuator_forcerange[a]
            elif m.jnt_actfrclimited[j]:
                lo[i], hi[i] = m.jnt_actfrcrange[j]
        #: (na,) torque limits [N m]
        self.torque_min, self.torque_max = lo, hi
        self.nv = int(m.nv)
        self._mass = np.zeros((self.nv, self.nv))
        self._new_full_m = not hasattr(data, "qM")
        self._jdot = np.zeros((6, self.nv))
        integrators = mujoco.mjtIntegrator
        implicit = (int(integrators.mjINT_IMPLICIT), int(integrators.mjINT_IMPLICITFAST))
        #: (nv,) ``h D`` added to the diagonal of ``M`` (see ``implicit_damping``), or None
        self.implicit_damping: FloatArray | None = None
        if implicit_damping and int(m.opt.integrator) in implicit and np.any(m.dof_damping > 0):
            self.implicit_damping = float(m.opt.timestep) * np.asarray(m.dof_damping, dtype=float)

    def set_torque_mode(self) -> None:
        """Make every actuator a motor: ``force = ctrl`` (clipped to its force range)."""
        m = self.m
        for a in self.actuators:
            m.actuator_gainprm[a, :] = 0.0
            m.actuator_gainprm[a, 0] = 1.0
            m.actuator_biasprm[a, :] = 0.0
            m.actuator_ctrllimited[a] = 0

    def dynamics(self) -> tuple[FloatArray, FloatArray]:
        """``M`` (nv, nv) and ``h`` (nv,) at the current state."""
        return self.mass_matrix().copy(), self.d.qfrc_bias - self.d.qfrc_passive

    def mass_matrix(self, out: FloatArray | None = None) -> FloatArray:
        """``M`` (nv, nv) at the current state, written into ``out`` (C-contiguous) or else into
        a buffer of this object that the next call overwrites (copy it to keep it)."""
        mass = self._mass if out is None else out
        if self._new_full_m:
            self.mj.mj_fullM(self.m, self.d, mass)
        else:  # MuJoCo < 3.5: mj_fullM(m, dst, qM)
            self.mj.mj_fullM(self.m, mass, self.d.qM)
        if self.implicit_damping is not None:
            mass.flat[:: self.nv + 1] += self.implicit_damping  # the diagonal, in place
        return mass

    def frame(
        self, body: int, point: FloatArray, angular: bool = True
    ) -> tuple[FloatArray, FloatArray]:
        """Jacobian (6, nv) of ``point`` (3,) [m] moving with ``body`` (linear rows, then
        angular) and its drift ``Jdot qd`` (6,); with ``angular`` False only the linear rows,
        (3, nv) and (3,)."""
        mj, m, d = self.mj, self.m, self.d
        pt = np.asarray(point, dtype=float)
        rows = 6 if angular else 3
        jac = np.empty((rows, self.nv))
        jdot = self._jdot[:rows]
        mj.mj_jac(m, d, jac[:3], jac[3:] if angular else None, pt, body)
        mj.mj_jacDot(m, d, jdot[:3], jdot[3:] if angular else None, pt, body)
        return jac, jdot @ d.qvel

    def jacobians(self, body: int, point: FloatArray, jac: FloatArray, jdot: FloatArray) -> None:
        """:meth:`frame` in place, without its drift product: the Jacobian of ``point`` (3,) [m]
        moving with ``body`` into ``jac`` and its time derivative into ``jdot``, both C-contiguous
        (3, nv) (linear rows) or (6, nv) (linear, then angular)."""
        mj, m, d = self.mj, self.m, self.d
        if jac.shape[0] == 3:
            mj.mj_jac(m, d, jac, None, point, body)
            mj.mj_jacDot(m, d, jdot, None, point, body)
        else:
            mj.mj_jac(m, d, jac[:3], jac[3:], point, body)
            mj.mj_jacDot(m, d, jdot[:3], jdot[3:], point, body)

    def contact(
        self,
        name: str,
        body: int,
        origin: FloatArray,
        points: FloatArray,
        normal: FloatArray,
        friction: float,
        min_normal: float = 0.0,
    ) -> Contact:
        """A :class:`~footfall.control.wbc.Contact` of ``body`` touching at ``points`` (k, 3)."""
        jac, drift = self.frame(body, origin)
        return Contact(
            name=name,
            jacobian=jac,
            drift=drift,
            origin=np.asarray(origin, dtype=float),
            points=np.asarray(points, dtype=float),
            normal=np.asarray(normal, dtype=float),
            friction=friction,
            min_normal=min_normal,
        )
