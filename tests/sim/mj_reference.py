"""Independent references from MuJoCo's own functions, shared by the whole-body controller tests."""

from __future__ import annotations

from typing import Any

import numpy as np


def inverse_dynamics_without_constraints(model: Any, data: Any, qacc: np.ndarray) -> np.ndarray:
    """``M(q) qacc + bias - passive`` at ``data``'s state, from ``mj_inverse`` with the
    constraint forces switched off (so the contact forces stay on the other side of the
    balance); a copy of ``qfrc_inverse`` (nv,). ``model``'s flags are restored afterwards."""
    import mujoco

    d2 = mujoco.MjData(model)
    d2.qpos[:], d2.qvel[:], d2.qacc[:] = data.qpos, data.qvel, qacc
    flags = model.opt.disableflags
    model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONSTRAINT)
    try:
        mujoco.mj_inverse(model, d2)
    finally:
        model.opt.disableflags = flags
    return np.array(d2.qfrc_inverse)
