"""The reconstructed Gonzalez baseline: small-signal law, saturation, signs, flight, validation."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import quadcruise as qc
from quadcruise.control import CONTROLLERS, Gonzalez, controller_from_name
from quadcruise.control.attitude import ATT_GAINS
from quadcruise.control.baselines import GONZALEZ_GAINS, GZ_COS_MAX_TILT, GZ_MAX_TILT, gonzalez, saturated_pd
from quadcruise.control.position import NLPD, nlpd
from quadcruise.errors import InputError
from quadcruise.layout import (
    CMD_FLAGS,
    CMD_PHI_D,
    CMD_SIZE,
    CMD_THETA_D,
    F1,
    FLAG_TILT_LIMIT,
    P_G,
    P_M,
    REF_SIZE,
    REF_X,
    REF_Y,
    REF_Z,
    STATE_SIZE,
    VX,
    VY,
    Z,
)
from quadcruise.model.vehicle import Vehicle

VP = Vehicle.paper().rows(1)[0].copy()


def command(controller, ex=0.0, ey=0.0, evx=0.0, evy=0.0, fn=None):
    """One control period from level hover at (0, 0, 1), the reference offset by the errors."""
    x = np.zeros(STATE_SIZE)
    x[Z] = 1.0
    x[F1 : F1 + 4] = VP[P_M] * VP[P_G] / 4.0
    x[VX], x[VY] = -evx, -evy
    ref = np.zeros(REF_SIZE)
    ref[REF_X], ref[REF_Y], ref[REF_Z] = ex, ey, 1.0
    cmd = np.zeros(CMD_SIZE)
    (fn or controller.function)(0.0, 1e-3, x, ref, VP, controller.gains(), controller.memory(), cmd)
    return cmd


def test_small_errors_give_the_linear_pd_through_u_over_g():
    c = Gonzalez()
    kp, kd, g = c.position.kp, c.position.kd, VP[P_G]
    e, ev = 1e-4, -3e-4
    cmd = command(c, ex=e, evx=ev, ey=-2e-4, evy=1e-4)
    assert cmd[CMD_THETA_D] == pytest.approx((kp * e + kd * ev) / g, rel=1e-6)
    assert cmd[CMD_PHI_D] == pytest.approx(-(kp * -2e-4 + kd * 1e-4) / g, rel=1e-6)
    assert cmd[CMD_FLAGS] == 0
    # to first order the paper's inverse model gives the same setpoints
    ref = command(NLPD(), ex=e, evx=ev, ey=-2e-4, evy=1e-4, fn=nlpd)
    assert cmd[CMD_THETA_D] == pytest.approx(ref[CMD_THETA_D], rel=1e-5)
    assert cmd[CMD_PHI_D] == pytest.approx(ref[CMD_PHI_D], rel=1e-5)


def test_saturation_bounds_the_law_and_the_tilt():
    kp, kd, ap, ad = 3.01, 5.0, 2.0, 1.5
    for e, ev in [(1e6, 1e6), (-1e6, 3e5), (50.0, -80.0), (1e-3, 0.0)]:
        assert abs(saturated_pd(e, ev, kp, kd, ap, ad)) <= ap + ad
    assert saturated_pd(1e6, 1e6, kp, kd, ap, ad) == pytest.approx(ap + ad)
    c = Gonzalez()  # default: literal k tanh(e) form
    assert (c.accel_p, c.accel_d) == pytest.approx((c.position.kp * 1.0, c.position.kd * 1.0))
    cmd = command(c, ex=1e4, evx=1e4, ey=-1e4, evy=-1e4)
    assert abs(cmd[CMD_THETA_D]) <= c.max_tilt + 1e-12 and abs(cmd[CMD_PHI_D]) <= c.max_tilt + 1e-12
    # levels beyond the tilt budget: the limit acts, exactly at max_tilt, and says so
    big = Gonzalez(accel_p=10.0, accel_d=10.0, max_tilt=math.radians(20.0))
    for sign in (1.0, -1.0):
        cmd = command(big, ex=sign * 1e4, ey=sign * 1e4)
        assert abs(cmd[CMD_THETA_D]) == pytest.approx(big.max_tilt, abs=1e-15)
        assert abs(cmd[CMD_PHI_D]) == pytest.approx(big.max_tilt, abs=1e-15)
        assert int(cmd[CMD_FLAGS]) & FLAG_TILT_LIMIT
    assert not int(command(big, ex=0.1)[CMD_FLAGS]) & FLAG_TILT_LIMIT


def test_signs_match_eqs_5_and_6():
    c = Gonzalez()
    assert command(c, ex=0.5)[CMD_THETA_D] > 0  # short of x: pitch up (x'' ~ sin theta)
    assert command(c, ex=-0.5)[CMD_THETA_D] < 0
    assert command(c, ey=0.5)[CMD_PHI_D] < 0  # short of y: roll negative (y'' ~ -sin phi)
    assert command(c, ey=-0.5)[CMD_PHI_D] > 0
    assert command(c, evx=0.5)[CMD_THETA_D] > 0 and command(c, evy=0.5)[CMD_PHI_D] < 0


def test_flies_the_step():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # duty clipping at the step instant
        res = qc.fly("step", controller="gonzalez", duration=10)
    assert res.ok.tolist() == [True]
    assert abs(res.final_state[0, 0] - 1.0) < 0.03
    assert np.abs(res.state("y")[0]).max() < 5e-3  # cross-coupling only (as for nlpd)


def test_flies_the_circle():
    res = qc.fly("circle", controller="gonzalez")
    assert res.ok.tolist() == [True]
    err = np.linalg.norm(res.states[0, :, :2] - res.references[0, :, :2], axis=1)
    assert err.max() <= 2.0 + 1e-6  # never worse than the initial 2 m offset
    assert err[res.t >= 10.0].max() < 0.1  # then tracks within 10 cm
    assert res.controller_limited_s[0] == 0.0


@pytest.mark.parametrize(
    "kwargs, name",
    [
        ({"max_tilt": 0.0}, "max_tilt"),
        ({"max_tilt": 1.6}, "max_tilt"),
        ({"accel_p": -1.0}, "accel_p"),
        ({"accel_d": float("nan")}, "accel_d"),
        ({"accel_p": "big"}, "accel_p"),
        ({"i_limit": 0.0}, "i_limit"),
        ({"i_limit": float("inf")}, "i_limit"),
        ({"position": (3.01, 5.0)}, "position"),
        ({"attitude": None}, "attitude"),
    ],
)
def test_bad_parameters_name_the_field(kwargs, name):
    with pytest.raises(InputError, match=f"gonzalez parameter '{name}'"):
        Gonzalez(**kwargs)


def test_registry_and_gains_layout():
    assert CONTROLLERS["gonzalez"] is Gonzalez
    c = controller_from_name("gonzalez", max_tilt=0.3)
    assert isinstance(c, Gonzalez) and c.accel_p == pytest.approx(3.01)
    g = c.gains()
    assert g.shape == (GONZALEZ_GAINS.size,) == (ATT_GAINS + 8,) and np.all(np.isfinite(g))
    assert g[GZ_MAX_TILT] == 0.3 and g[GZ_COS_MAX_TILT] == math.cos(0.3)
    np.testing.assert_array_equal(g[:ATT_GAINS], NLPD().gains()[:ATT_GAINS])  # same attitude loop
    assert c.to_dict()["name"] == "gonzalez" and c.function is gonzalez


def test_docstring_examples_run():
    import doctest

    from quadcruise.control import baselines

    assert doctest.testmod(baselines, raise_on_error=False, optionflags=doctest.ELLIPSIS).failed == 0
