"""Shared test settings: named tolerances."""

#: agreement between closed-form/discrete models and a tight solve_ivp integration
INTEGRATION_TOL = 1e-7
#: solve_ivp tolerances used as the independent reference
IVP_RTOL = 1e-11
IVP_ATOL = 1e-12
