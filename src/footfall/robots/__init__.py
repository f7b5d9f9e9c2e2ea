"""Robots as data: robot files (YAML) naming a URDF or MJCF model, and what footfall derives from
the model (mass, CoM height, nominal posture, sole, limits, reach, timing)."""
