"""Control allocation for any layout: the "+" case is the paper's eqs (1)-(4), the "x" quad is
RotorPy's allocator, a hexarotor makes the wrench asked of it, and an allocation that cannot
be made is refused or reported."""

from __future__ import annotations

import math

import numpy as np
import pytest

from quadcruise import InputError, Vehicle
from quadcruise.model.actuators import mix, unmix
from quadcruise.model.allocation import allocation_matrix, mixer, rotor_speeds, thrusts
from quadcruise.model.rotor_vehicle import RotorVehicle

PAPER = Vehicle.paper()


def plus_quad(l, d):
    """The paper's "+" layout as a rotor vehicle: rotor 2 on +y (U2 = F2 - F4 rolls about +x),
    rotor 1 behind (U3 = F1 - F3 pitches about +y), rotors 1 and 3 pushing yaw +z (U4 = d (F1 + F3 - ...))."""
    kf = 1.0e-5
    return RotorVehicle(
        m=PAPER.m,
        Jxx=PAPER.Jxx,
        Jyy=PAPER.Jyy,
        Jzz=PAPER.Jzz,
        kf=kf,
        km=d * kf,
        tau_up=0.05,
        tau_down=0.05,
        w_min=0.0,
        w_max=2000.0,
        rotors=[[-l, 0, 0, 1], [0, l, 0, -1], [l, 0, 0, 1], [0, -l, 0, -1]],
    )


@pytest.mark.parametrize("U", [(40.0, 1.5, -0.7, 0.2), (34.3, 0.0, 0.0, 0.0), (10.0, -3.0, 2.0, -1.0)])
def test_the_plus_case_is_the_papers_eqs_1_to_4(U):
    l, d = float(PAPER.l), float(PAPER.d)
    v = plus_quad(l, d)
    U1, U2, U3, U4 = U
    f = thrusts(v, U1, (U2 * l, U3 * l, U4))  # eq (11): torques U2 l, U3 l and U4
    np.testing.assert_allclose(f, unmix(U1, U2, U3, U4, d), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(mix(*f, d), U, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("name", ["crazyflie", "hummingbird"])
def test_the_x_quad_is_rotorpys_allocator(name):
    rotorpy = pytest.importorskip("rotorpy.vehicles.multirotor")
    import importlib

    params = importlib.import_module(f"rotorpy.vehicles.{name}_params").quad_params
    theirs = rotorpy.Multirotor(params)
    v = RotorVehicle.preset(name)
    np.testing.assert_allclose(allocation_matrix(v), theirs.f_to_TM, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(mixer(v), theirs.TM_to_f, rtol=1e-9, atol=1e-12)


def test_a_hexarotor_makes_the_wrench_with_the_least_thrusts():
    hexa = [[0.25 * math.cos(k * math.pi / 3), 0.25 * math.sin(k * math.pi / 3), 0.0, (-1) ** k] for k in range(6)]
    v = RotorVehicle.preset("iris").replace(rotors=hexa, m=2.0)
    want = np.array([25.0, 0.3, -0.2, 0.05])
    f = thrusts(v, want[0], want[1:])
    np.testing.assert_allclose(allocation_matrix(v) @ f, want, rtol=1e-12, atol=1e-12)
    # any other set of thrusts that makes the same wrench differs by a null-space vector and is larger
    null = np.linalg.svd(allocation_matrix(v))[2][-1]
    assert np.linalg.norm(f + 0.1 * null) > np.linalg.norm(f)
    speeds, clipped = rotor_speeds(v, f)
    np.testing.assert_allclose(v.kf * speeds**2, f, rtol=1e-12)
    assert not clipped.any()


def test_a_layout_that_cannot_yaw_is_refused():
    v = RotorVehicle.preset("crazyflie")
    same_way = [[r[0], r[1], r[2], 1.0] for r in v.rotors]
    with pytest.raises(InputError, match="rank 3 of 4"):
        mixer(v.replace(rotors=same_way))
    with pytest.raises(InputError, match="rank 3 of 4"):
        mixer(v.replace(km=0.0))


def test_speeds_beyond_the_range_are_held_and_reported():
    v = RotorVehicle.preset("crazyflie")
    f = np.array([-0.01, 0.0, 0.07, 0.2])  # 0.2 N > kf w_max^2 = 0.14375 N
    speeds, clipped = rotor_speeds(v, f)
    assert speeds.tolist()[:2] == [0.0, 0.0] and speeds[3] == v.w_max
    assert clipped.tolist() == [True, False, False, True]


def test_the_plus_layout_on_the_rotor_plant_feels_the_paper_plants_torques():
    """The same four thrusts on both plants, at rest and level: the same accelerations (so the
    layout above is the paper's, not only its algebra)."""
    from quadcruise.layout import EXT_E1, EXT_SIZE, F1, STATE_SIZE
    from quadcruise.model.plant import derivative
    from quadcruise.model.rotor_plant import ROTOR_W1, rotor_derivative

    l, d = float(PAPER.l), float(PAPER.d)
    v = plus_quad(l, d)
    F = np.array([9.0, 7.5, 8.0, 10.0])
    x = np.zeros(STATE_SIZE)
    x[F1 : F1 + 4] = F
    ext = np.zeros(EXT_SIZE)
    ext[EXT_E1:] = 1.0
    dx = np.zeros(STATE_SIZE)
    derivative(x, F / float(PAPER.K), PAPER.rows()[0], ext, False, dx)
    xr = np.zeros(ROTOR_W1 + 4)
    xr[6] = 1.0
    xr[ROTOR_W1:] = np.sqrt(F / v.kf)
    dxr = np.zeros(ROTOR_W1 + 4)
    rotor_derivative(xr, xr[ROTOR_W1:].copy(), v.row(), np.r_[np.zeros(9), np.ones(4)], dxr)
    np.testing.assert_allclose(dxr[3:6], dx[3:6], rtol=1e-12, atol=1e-12)  # x'', y'', z''
    np.testing.assert_allclose(dxr[10:13], dx[9:12], rtol=1e-12, atol=1e-12)  # p', q', r'
