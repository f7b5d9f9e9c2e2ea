"""The records every plant returns, below both the simulation and the figures: the
:class:`Outcome` of a trial (the same fields for every plant) and each plant's full record."""

from footfall.results.outcome import OUTCOME_COLUMNS, Outcome
from footfall.results.quadruped import QuadrupedMetrics, QuadrupedResult, QuadrupedTrace
from footfall.results.reduced import SimMetrics, SimResult
from footfall.results.walk import WalkMetrics, WalkResult, WalkTrace

__all__ = [
    "OUTCOME_COLUMNS",
    "Outcome",
    "QuadrupedMetrics",
    "QuadrupedResult",
    "QuadrupedTrace",
    "SimMetrics",
    "SimResult",
    "WalkMetrics",
    "WalkResult",
    "WalkTrace",
]
