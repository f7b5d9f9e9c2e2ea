"""Matplotlib figures of terrains, plans and simulations."""
