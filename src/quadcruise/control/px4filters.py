"""PX4's gyro filters, compiled: the angular velocity low-pass (``IMU_GYRO_CUTOFF``) and the
D-term low-pass of the differenced raw rate (``IMU_DGYRO_CUTOFF``).

As PX4 v1.15's ``src/modules/sensors/vehicle_angular_velocity/VehicleAngularVelocity.cpp``
filters: the rate through ``math::LowPassFilter2p`` (a second-order Butterworth, bilinear with
the cutoff prewarped, Direct Form II), and the angular acceleration as the backward difference
of the *unfiltered* rate through an ``AlphaFilter`` (first order,
``alpha = dt / (dt + 1 / (2 pi f_c))``). A cutoff of 0, or at or above half the sample rate,
disables a filter (it passes its input), as PX4's ``setCutoffFreq`` refuses it.
"""

from __future__ import annotations

import math

from numba import njit

__all__ = ["lpf2p_coefficients", "lpf2p_reset", "lpf2p_apply", "alpha_of", "alpha_apply"]


@njit(cache=True)
def lpf2p_coefficients(sample_hz, cutoff_hz):
    """``LowPassFilter2p::set_cutoff_frequency``: ``(b0, b1, b2, a1, a2)``; ``(1, 0, 0, 0, 0)``
    (a pass-through) for a cutoff of 0 or at or above half the sample rate.

    Examples
    --------
    >>> [round(c, 6) for c in lpf2p_coefficients(800.0, 40.0)]
    [0.020083, 0.040167, 0.020083, -1.561018, 0.641352]
    """
    if sample_hz <= 0.0 or cutoff_hz <= 0.0 or cutoff_hz >= sample_hz / 2.0:
        return (1.0, 0.0, 0.0, 0.0, 0.0)
    cutoff_hz = max(cutoff_hz, sample_hz * 0.001)
    ohm = math.tan(math.pi / (sample_hz / cutoff_hz))
    c = 1.0 + 2.0 * math.cos(math.pi / 4.0) * ohm + ohm * ohm
    b0 = ohm * ohm / c
    return (b0, 2.0 * b0, b0, 2.0 * (ohm * ohm - 1.0) / c, (1.0 - 2.0 * math.cos(math.pi / 4.0) * ohm + ohm * ohm) / c)


@njit(cache=True, inline="always")
def lpf2p_reset(coefficients, sample):
    """``LowPassFilter2p::reset``: the two delay elements of a filter settled at ``sample``."""
    a1, a2 = coefficients[3], coefficients[4]
    value = sample if math.isfinite(sample) else 0.0
    if abs(1.0 + a1 + a2) > 1.1920929e-07:
        value = value / (1.0 + a1 + a2)
    return (value, value)


@njit(cache=True, inline="always")
def lpf2p_apply(coefficients, delay, sample):
    """``LowPassFilter2p::apply`` (Direct Form II): ``(output, new delay elements)``."""
    b0, b1, b2, a1, a2 = coefficients
    d0 = sample - delay[0] * a1 - delay[1] * a2
    return d0 * b0 + delay[0] * b1 + delay[1] * b2, (d0, delay[0])


@njit(cache=True, inline="always")
def alpha_of(sample_hz, cutoff_hz):
    """``AlphaFilter::setCutoffFreq``: ``dt / (dt + 1 / (2 pi f_c))``; 1 (no filtering) where PX4
    refuses the cutoff (0, or at or above half the sample rate).

    Examples
    --------
    >>> round(alpha_of(800.0, 30.0), 6)
    0.190689
    """
    if sample_hz <= 0.0 or cutoff_hz <= 0.0 or cutoff_hz >= sample_hz / 2.0:
        return 1.0
    dt = 1.0 / sample_hz
    return dt / (dt + 1.0 / (2.0 * math.pi * cutoff_hz))


@njit(cache=True, inline="always")
def alpha_apply(alpha, state, sample):
    """``AlphaFilter::update``: ``state + alpha (sample - state)``, the new state and output."""
    return state + alpha * (sample - state)
