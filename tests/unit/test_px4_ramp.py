"""PX4's takeoff ramp and the land detector's takeoff in the px4 controller's compiled step
(``quadcruise.control.px4kernel._takeoff_step``), against PX4's own unit test
(``src/modules/mc_pos_control/Takeoff/TakeoffTest.cpp``, ``RegularTakeoffRamp``: its inputs and
expected values restated) and ``MulticopterLandDetector``'s threshold."""

from __future__ import annotations

import math

import numpy as np
import pytest

from quadcruise.control import px4kernel as K
from quadcruise.control.px4 import Px4
from quadcruise.control.px4loops import G_THR_HOVER, G_THR_MIN, G_TILT_MAX, G_VEL_P, G_VMAX_UP, ONE_G, PX4_GAINS


def ramp_state(ramp_time=2.0, target=1.5, vel_p_z=ONE_G / 0.5, vmax_up=10.0):
    """A controller's memory at the first step of the ramp, as ``_ground_start`` leaves it."""
    c = Px4(takeoff=True, hover_from_vehicle=False, rate_bandwidth=0.0)
    gains = c.gains()
    gains[K.X_TKO_RAMP_T], gains[K.X_TKO_SPEED_UP] = ramp_time, target
    g = gains[: PX4_GAINS.size].copy()
    g[G_VEL_P + 2], g[G_VMAX_UP] = vel_p_z, vmax_up
    mem = c.memory()
    K._ground_start(mem, gains, g)
    return mem, gains, g


def test_regular_takeoff_ramp():
    """RegularTakeoffRamp: ramp time 2 s, the initial value -g / (g / 0.5) = -0.5 m/s, the target
    1.5 m/s, steps of 0.5 s: the climb limit 0, 0.5, 1, 1.5, 1.5; flight after the ramp."""
    mem, gains, g = ramp_state()
    limits, states = [], []
    for _ in range(5):
        K._takeoff_step(mem, gains, g, 0.5, 0.0)
        limits.append(g[G_VMAX_UP])
        states.append(mem[K.Y_TKO_STATE])
    assert limits == pytest.approx([0.0, 0.5, 1.0, 1.5, 1.5], abs=1e-12)
    assert states[:4] == [K.TAKEOFF_RAMPUP] * 4 and states[4] == K.TAKEOFF_FLIGHT


def test_the_ramp_starts_from_no_thrust_and_limits_until_flight():
    """Before flight the minimum thrust is 0 (PX4: 'allow ramping from zero thrust'), the hover
    thrust the parameter, the tilt limit MPC_TILTMAX_LND slewing at 0.2 rad/s to MPC_TILTMAX_AIR
    once flying; the climb target is capped at MPC_Z_VEL_MAX_UP (the flight task's faster climb
    is not ramped to)."""
    mem, gains, g = ramp_state(ramp_time=0.5, target=3.6, vmax_up=3.0)
    thr_min = mem[K.Y_THR_MIN_PARAM]
    assert thr_min > 0.0
    K._takeoff_step(mem, gains, g, 0.25, 0.0)
    assert g[G_THR_MIN] == 0.0 and mem[K.Y_TILT] == pytest.approx(math.radians(12.0))
    K._takeoff_step(mem, gains, g, 0.25, 0.0)  # progress 1: the climb limit is the capped target
    assert g[G_VMAX_UP] == 3.0
    flying = K._takeoff_step(mem, gains, g, 0.25, 0.0)
    assert flying and g[G_THR_MIN] == thr_min
    assert mem[K.Y_TILT] == pytest.approx(math.radians(12.0) + 0.2 * 0.25)
    for _ in range(40):
        K._takeoff_step(mem, gains, g, 0.25, 0.0)
    assert mem[K.Y_TILT] == g[G_TILT_MAX]


@pytest.mark.parametrize("thrust, landed", [(0.157, True), (0.159, False)])
def test_the_land_detector_lets_go_above_its_minimum_thrust(thrust, landed):
    """MulticopterLandDetector: maybe landed while the thrust is at most MPC_THR_MIN + 0.1 (hover -
    MPC_THR_MIN) = 0.12 + 0.1 (0.5 - 0.12) = 0.158 (the SITL log's parameters; it reported 'not
    landed' at 16.74 s, as its thrust setpoint crossed 0.158); in the air, for the estimator,
    once not landed and over 1 m."""
    mem, gains, g = ramp_state()
    g[G_THR_MIN], g[G_THR_HOVER] = 0.12, 0.5
    mem[K.Y_THR_MIN_PARAM] = 0.12
    mem[K.Y_THRUST] = thrust
    K._takeoff_step(mem, gains, g, 0.01, 0.5)
    assert bool(mem[K.Y_LANDED] == 1.0) is landed and mem[K.Y_IN_AIR] == 0.0
    mem[K.Y_THRUST] = 0.5
    K._takeoff_step(mem, gains, g, 0.01, 1.2)
    assert mem[K.Y_LANDED] == 0.0 and mem[K.Y_IN_AIR] == 1.0
    assert np.isfinite(g).all()
