"""Closed-loop flights of rotor-plant vehicles: every preset flies the circle with se3, cascade and
nlpd; the paper-layout state the controllers see is the rotor state's (scipy's Euler angles);
an Iris losing 60 % of a rotor over the ground crashes, a healthy one does not; bad input is one line."""

import subprocess
import sys
import warnings

import numpy as np
import pandas as pd
import pytest
from scipy.spatial.transform import Rotation

import quadcruise as qc
from quadcruise.disturbances import ConstantWind, Environment, RotorLoss, SensorNoise
from quadcruise.errors import FlightWarning, InputError
from quadcruise.missions import Hover
from quadcruise.model.equivalent import duty_to_thrust, paper_equivalent
from quadcruise.model.rotor_vehicle import RotorVehicle
from quadcruise.sim.status import ExitStatus

PRESETS = ("paper", "qball-x4", "crazyflie", "hummingbird", "iris")


@pytest.mark.parametrize("preset", PRESETS)
@pytest.mark.parametrize("controller", ("se3", "cascade", "nlpd"))
def test_each_preset_flies_the_circle(preset, controller):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the start's 2 m offset saturates some rotors briefly
        res = qc.fly("circle", controller, vehicle=preset)
    assert res.status_text(0) == "finished"
    err = np.linalg.norm(res.states[0, :, :3] - res.references[0, :, :3], axis=1)
    assert err[res.t > 10.0].max() < 1.0  # on its circle after the start, not just inside the bounds
    if preset not in ("paper", "qball-x4"):
        assert res.rotor_states is not None and res.meta["vehicle"]["plant"] == "rotor"


def test_the_controller_sees_the_rotor_state_in_the_paper_layout():
    v = RotorVehicle.preset("crazyflie")
    res = qc.fly("circle", "se3", vehicle=v, duration=3.0)
    q = res.rotor_states[0, :, 6:10]
    zyx = Rotation.from_quat(q, scalar_first=True).as_euler("ZYX")[:, ::-1]
    np.testing.assert_allclose(res.states[0, :, 6:9], zyx, atol=1e-12)
    np.testing.assert_array_equal(res.states[0, :, :6], res.rotor_states[0, :, :6])
    np.testing.assert_allclose(res.states[0, :, 12:16], v.kf * res.rotor_states[0, :, 13:17] ** 2, rtol=1e-12)
    frame = res.to_pandas()
    assert {"qw", "w4", "phi", "F1"} <= set(frame.columns)
    assert np.isfinite(res.metrics()["effort"][0])  # the hover duty of its paper equivalent


def test_the_yaw_is_continuous_beyond_pi():
    res = qc.fly(Hover(yaw=4.0), "se3", vehicle="iris", duration=2.0)  # 4 rad: the quaternion's is 4 - 2 pi
    assert res.status_text(0) == "finished"
    np.testing.assert_allclose(res.states[0, :, 8], 4.0, atol=1e-6)


def test_the_plus_equivalent_duties_make_the_wrench_they_mean():
    v = RotorVehicle.preset("iris")
    eq = paper_equivalent(v)
    u = np.array([0.6, 0.5, 0.4, 0.55])
    f = duty_to_thrust(v) @ u
    F = eq.K * u  # the "+" vehicle's thrusts, eqs (1)-(4)
    rotors = np.asarray(v.rotors)
    wrench = [f.sum(), rotors[:, 1] @ f, -rotors[:, 0] @ f, (rotors[:, 3] * v.km / v.kf) @ f]
    want = [F.sum(), eq.l * (F[1] - F[3]), eq.l * (F[0] - F[2]), eq.d * (F[0] + F[2] - F[1] - F[3])]
    np.testing.assert_allclose(wrench, want, rtol=1e-12, atol=1e-12)
    assert eq.omega == 1.0 / max(v.tau_up, v.tau_down) and eq.m == v.m and eq.drag_linear == 0.0


def test_an_iris_losing_60_percent_of_a_rotor_crashes_and_a_healthy_one_does_not():
    loss = Environment(rotor_loss=RotorLoss(rotor=1, fraction=0.6, time=1.0))
    with pytest.warns(FlightWarning, match="crashed"):
        res = qc.fly("hover", "se3", vehicle="iris", environment=loss, duration=5.0)
    assert res.exit_status(0) == ExitStatus.CRASHED and 1.0 < res.t_stop[0] < 5.0
    assert res.rotor_final_state[0, 2] < 0.0  # it met the ground
    healthy = qc.fly("hover", "se3", vehicle="iris", duration=5.0)
    assert healthy.status_text(0) == "finished"
    assert abs(healthy.final_state[0, 2] - 1.0) < 0.01


def test_batches_reproduce_single_flights():
    one = qc.fly("circle", "cascade", vehicle="iris", duration=2.0)
    three = qc.fly("circle", "cascade", vehicle="iris", duration=2.0, n=3)
    for i in range(3):
        np.testing.assert_array_equal(three.rotor_states[i], one.rotor_states[0])


def test_a_rotor_vehicle_it_cannot_fly_is_one_line():
    tri = RotorVehicle.preset("iris").replace(rotors=[[0.2, 0.0, 0.0, 1], [-0.1, 0.17, 0.0, -1], [-0.1, -0.17, 0.0, 1]])
    with pytest.raises(InputError, match="rank 3 of 4"):
        qc.fly("hover", "se3", vehicle=tri, duration=1.0)
    with pytest.raises(InputError, match="one plant"):
        qc.fly("hover", "se3", vehicle="iris", controller_vehicle=qc.Vehicle.paper(), duration=1.0)
    with pytest.raises(InputError, match="full_dynamics"):
        qc.fly("hover", "se3", vehicle="iris", full_dynamics=True, duration=1.0)
    with pytest.raises(InputError, match="unknown vehicle preset 'irs'"):
        qc.fly("hover", "se3", vehicle="irs", duration=1.0)


def quadcruise(*args, cwd):
    return subprocess.run(
        [sys.executable, "-m", "quadcruise", *map(str, args)], capture_output=True, text=True, cwd=cwd, timeout=300
    )


def test_the_command_line_flies_a_preset_and_its_scenario_flies_it_again(tmp_path):
    first = quadcruise(
        "fly", "circle", "--vehicle", "iris", "--controller", "se3", "--duration", "4", "--out", "a", cwd=tmp_path
    )
    assert first.returncode == 0, first.stderr
    again = quadcruise("fly", "a/scenario.toml", "--out", "b", cwd=tmp_path)
    assert again.returncode == 0, again.stderr
    a, b = (pd.read_csv(tmp_path / d / "traces.csv") for d in "ab")
    assert {"qw", "w4"} <= set(a.columns)
    pd.testing.assert_frame_equal(a, b)


@pytest.mark.parametrize(
    "args, words",
    [
        (["fly", "hover", "--wind", "constant:2,0,0", "--duration", "1"], "has none"),
        (["fly", "hover", "--controller-vehicle", "paper", "--duration", "1"], "of one plant"),
        (["tune", "step", "--minimize", "rmse_m", "--wind-spread", "1", "--duration", "1"], "has none"),
    ],
)
def test_what_the_rotor_plant_cannot_do_is_one_line_exit_2(tmp_path, args, words):
    vehicle = "iris,k_d=0" if any(a.startswith("--wind") for a in args) else "iris"
    proc = quadcruise(*args, "--vehicle", vehicle, cwd=tmp_path)
    assert proc.returncode == 2, proc.stderr
    errors = [ln for ln in proc.stderr.splitlines() if ln.startswith("error: ")]
    assert len(errors) == 1 and words in errors[0] and "Traceback" not in proc.stderr
    assert not proc.stdout.strip()  # refused before anything flew


def test_a_hexarotor_flies_through_the_least_squares_mixer():
    iris = RotorVehicle.preset("iris")
    a = np.radians(np.arange(6) * 60.0 + 30.0)
    rotors = [[0.25 * np.cos(t), 0.25 * np.sin(t), 0.02, (-1) ** k] for k, t in enumerate(a)]
    hexa = iris.replace(rotors=rotors, m=2.0)
    res = qc.fly("circle", "se3", vehicle=hexa)
    assert res.status_text(0) == "finished" and res.rotor_states.shape[2] == 13 + 6
    err = np.linalg.norm(res.states[0, :, :3] - res.references[0, :, :3], axis=1)
    assert err[res.t > 10.0].max() < 1.0
    w = res.rotor_states[0, -1, 13:]
    assert np.allclose(w, w.mean(), rtol=0.05)  # B+: the least thrusts share the load


def test_sensor_noise_and_delay_reach_the_controller_and_repeat_with_the_seed():
    sensors = SensorNoise(position_std=0.01, delay=0.01)
    clean = qc.fly("hover", "se3", vehicle="crazyflie", duration=3.0)
    a = qc.fly("hover", "se3", vehicle="crazyflie", duration=3.0, sensors=sensors, seed=3)
    b = qc.fly("hover", "se3", vehicle="crazyflie", duration=3.0, sensors=sensors, seed=3)
    c = qc.fly("hover", "se3", vehicle="crazyflie", duration=3.0, sensors=sensors, seed=4)
    np.testing.assert_array_equal(a.rotor_states, b.rotor_states)
    assert not np.array_equal(a.rotor_states, c.rotor_states)
    assert 0.0 < np.abs(a.states[0, :, :3] - clean.states[0, :, :3]).max() < 0.05
    assert a.status_text(0) == "finished"


def test_wind_pushes_a_vehicle_with_rotor_drag_and_it_leans_into_it():
    calm = qc.fly("hover", "se3", vehicle="iris", duration=5.0)
    windy = qc.fly(
        "hover", "se3", vehicle="iris", duration=5.0, environment=Environment(wind=ConstantWind((3.0, 0, 0)))
    )
    assert calm.states[0, -1, 7] == pytest.approx(0.0, abs=1e-9)
    assert windy.states[0, -1, 7] < -0.02  # pitched against the wind (+theta accelerates +x)
    assert windy.final_state[0, 0] > 0.05  # se3 has no integrator: blown downwind


def test_model_error_the_controller_believes_another_rotor_vehicle():
    iris = RotorVehicle.preset("iris")
    heavier = qc.fly("hover", "se3", vehicle=iris.replace(m=1.05 * iris.m), controller_vehicle=iris, duration=12.0)
    assert heavier.status_text(0) == "finished"
    assert heavier.meta["controller_vehicle"]["m"] == iris.m and heavier.meta["vehicle"]["m"] == 1.05 * iris.m
    # se3 has no integrator: m (kz e + g) = 1.05 m g holds it e = 0.05 g / kz below its reference
    kz = qc.control.SE3().altitude.kp
    assert 1.0 - heavier.final_state[0, 2] == pytest.approx(0.05 * iris.g / kz, rel=0.02)
    hexa = iris.replace(
        rotors=[[0.25 * np.cos(a), 0.25 * np.sin(a), 0.0, (-1) ** k] for k, a in enumerate(np.arange(6))]
    )
    with pytest.raises(InputError, match="6 rotors, the flown vehicle 4"):
        qc.fly("hover", "se3", vehicle=iris, controller_vehicle=hexa, duration=1.0)
