"""The MuJoCo biped plant: models (ours and the Unitree G1), the walking controller, its metrics."""
