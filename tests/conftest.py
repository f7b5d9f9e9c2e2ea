"""Shared test settings: named tolerances, headless rendering."""

import os

# MuJoCo picks its GL backend at import; offscreen EGL works headless (tests that render say so).
os.environ.setdefault("MUJOCO_GL", "egl")


#: agreement between closed-form/discrete models and a tight solve_ivp integration
INTEGRATION_TOL = 1e-7
#: solve_ivp tolerances used as the independent reference
IVP_RTOL = 1e-11
IVP_ATOL = 1e-12
