"""Reduced-order dynamics: Kajita's LIP (document 004) and the ALIP with ankle torque (document 000)."""

from footfall.models._linear import zoh
from footfall.models.alip import ALIP
from footfall.models.lip import GRAVITY, LIP

__all__ = ["ALIP", "GRAVITY", "LIP", "zoh"]
