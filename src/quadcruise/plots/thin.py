"""Which logged samples a drawing keeps."""

from __future__ import annotations

import numpy as np

__all__ = ["thinned"]


def thinned(first: int, last: int, step: int) -> np.ndarray:
    """Log indices first, first + step, ... up to ``last``, and ``last`` itself.

    Examples
    --------
    >>> thinned(0, 10, 4)
    array([ 0,  4,  8, 10])
    """
    return np.unique(np.r_[np.arange(first, last + 1, max(1, int(step))), last])
