"""Simulation: reduced-order closed loops and MuJoCo models."""
