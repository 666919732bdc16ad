"""Tuning: any controller's gains, searched within bounds against targets, requirements and
metrics to minimise, each generation of candidates flown as one batch, on the nominal vehicle
or over a Monte Carlo population (the worst case or a quantile).

- :mod:`quadcruise.tune.criteria`: targets, requirements, minimised metrics, and
  :mod:`quadcruise.tune.space`: gains by name (or by pole pair) and their bounds; small
  frozen objects (or plain mappings) checked before any flight;
- :mod:`quadcruise.tune.objective`: a generation -> one batched flight -> metrics -> costs;
- :mod:`quadcruise.tune.search`: :func:`tune`, scipy's differential evolution;
- :mod:`quadcruise.tune.result`: :class:`TuneResult` (``to_pandas``, ``summary``, ``plot``,
  ``write``: a folder with a ``scenario.toml`` that ``quadcruise fly`` flies).
"""

from quadcruise.tune.criteria import Requirement, Target
from quadcruise.tune.result import TuneResult
from quadcruise.tune.search import tune
from quadcruise.tune.space import Bounds, GainSpace

__all__ = ["Bounds", "GainSpace", "Requirement", "Target", "TuneResult", "tune"]
