"""System identification: a flight log in, the vehicle's parameters out (:func:`identify`).

See docs/identify.md for the estimator and why.
"""

from quadcruise.sysid.api import identify
from quadcruise.sysid.result import IdentifyResult

__all__ = ["IdentifyResult", "identify"]
