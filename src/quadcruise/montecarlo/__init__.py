"""Monte Carlo: a population of perturbed vehicles flown in chunks, in process or on Dask,
reduced to metrics, streamed to disk and resumable."""

from quadcruise.montecarlo.api import montecarlo
from quadcruise.montecarlo.chunk import Case, montecarlo_case, replay_case
from quadcruise.montecarlo.population import Draw, Population
from quadcruise.montecarlo.requirements import Requirement
from quadcruise.montecarlo.result import MonteCarloResult
from quadcruise.montecarlo.spec import MonteCarloSpec

__all__ = [
    "Case",
    "Draw",
    "MonteCarloResult",
    "MonteCarloSpec",
    "Population",
    "Requirement",
    "montecarlo",
    "montecarlo_case",
    "replay_case",
]
