"""Which logged samples a drawing keeps."""

from __future__ import annotations

import numpy as np

__all__ = ["thinned"]


def thinned(first: int, last: int, step: int) -> np.ndarray:
    """Log indices first, first + step, ... up to ``last``, and ``last`` itself.

    A path thinned for drawing keeps its end.

    Parameters
    ----------
    first : int
        The first index.
    last : int
        The last index, always included.
    step : int
        The step between indices (1 if less than 1).

    Returns
    -------
    ndarray of int
        The indices, sorted, without repeats.

    Examples
    --------
    >>> thinned(0, 10, 4)
    array([ 0,  4,  8, 10])
    """
    return np.unique(np.r_[np.arange(first, last + 1, max(1, int(step))), last])
