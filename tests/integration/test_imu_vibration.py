"""The IMU's vibration term on the rotor plant (issue 35): the rotors' imbalance read through the
IMU's period average, checked against an independent quadrature of the logged rotor speeds."""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest

import quadcruise as qc
from quadcruise import layout as L
from quadcruise.errors import InputError
from quadcruise.estimation import Ekf, Sensors
from quadcruise.estimation.stage import PRESETS
from quadcruise.gym.env import QuadVectorEnv
from quadcruise.model.rotor_vehicle import RotorVehicle
from quadcruise.montecarlo.population import Population
from quadcruise.montecarlo.spec import MonteCarloSpec
from quadcruise.sensors import Imu
from quadcruise.sim.observe import sensor_streams
from quadcruise.sim.rng import next_unit


def _flight(vibration, seed=3, duration=0.4, rate=250.0):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return qc.fly(
            "hover", "nlpd", vehicle="iris", duration=duration, seed=seed,
            sensors=Sensors(imu=Imu(rate=rate, vibration=vibration)),
        ).to_pandas()  # fmt: skip


def _quadrature(w, dt, every, amplitude, vehicle, phases):
    """Each IMU period's mean of sum_i a_i (cos phi_i, sin phi_i), phi_i piecewise linear in t,
    integrated with 16-point Gauss-Legendre per control period (w: (K + 1, n) speeds at the
    periods' ends)."""
    s = np.array([r[3] for r in vehicle.rotors])
    w_hover2 = vehicle.m * vehicle.g / (vehicle.n_rotors * vehicle.kf)
    mid = 0.5 * (w[1:] + w[:-1])  # (K, n) each period's mean speed
    angle = phases[None, :] + np.vstack([np.zeros(len(s)), np.cumsum(-s * mid * dt, axis=0)])  # at the ends
    nodes, weights = np.polynomial.legendre.leggauss(16)
    tau = 0.5 * (nodes + 1.0)  # fractions of the period
    phi = angle[:-1, None, :] + tau[None, :, None] * (angle[1:] - angle[:-1])[:, None, :]  # (K, 16, n)
    a = amplitude * mid**2 / w_hover2
    fx = (0.5 * weights[None, :, None] * a[:, None, :] * np.cos(phi)).sum(axis=(1, 2))  # each period's mean
    fy = (0.5 * weights[None, :, None] * a[:, None, :] * np.sin(phi)).sum(axis=(1, 2))
    k = len(fx) // every
    return fx[: k * every].reshape(k, every).mean(axis=1), fy[: k * every].reshape(k, every).mean(axis=1)


def test_the_averaged_vibration_is_the_quadrature_of_the_logged_rotor_speeds():
    amplitude, seed = 4.0, 3
    on, off = _flight(amplitude, seed), _flight(0.0, seed)
    # the controller reads the truth (no estimator): both flights fly the same rotor speeds
    w = on[["w1", "w2", "w3", "w4"]].to_numpy()
    assert np.array_equal(w, off[["w1", "w2", "w3", "w4"]].to_numpy())
    dt, every = 1e-3, 4  # the default control period, a 250 Hz IMU
    assert np.allclose(np.diff(on["t"]), dt)
    state = sensor_streams(seed, 1)[0, 0]  # the rotors' angles: the stream's first draws
    phases = np.empty(L.MAX_VIBRATING_ROTORS)
    for r in range(L.MAX_VIBRATING_ROTORS):
        u, state = next_unit(np.uint64(state))  # a Python int back: uint64 again, as the kernel's
        phases[r] = 2.0 * np.pi * u
    vehicle = RotorVehicle.preset("iris")
    want_x, want_y = _quadrature(w, dt, every, amplitude, vehicle, phases[:4])
    instants = np.arange(every, len(w), every)  # the IMU's readings after the first (a point at switch-on)
    got = on[["accel_x", "accel_y", "accel_z"]].to_numpy() - off[["accel_x", "accel_y", "accel_z"]].to_numpy()
    got = got[instants]
    n = len(instants)
    assert np.abs(got[:, 0] - want_x[:n]).max() < 1e-9 and np.abs(got[:, 1] - want_y[:n]).max() < 1e-9
    assert np.abs(got[:, 2]).max() == 0.0  # in the rotors' plane
    assert np.abs(got[:, :2]).max() > 1.0  # a vibration there to read
    # the average is not a point sample of the vibration at the reading's instant
    a = amplitude * w**2 / (vehicle.m * vehicle.g / (vehicle.n_rotors * vehicle.kf))
    assert np.abs(got[:, 0] - want_x[:n]).max() < 1e-3 * np.abs(got[:, 0] - a[instants].sum(axis=1)).max()
    # the first reading (switch-on) has none: the stream's angles differ with the seed
    assert np.all(got[0] == got[0]) and not np.array_equal(_flight(amplitude, seed + 1)["accel_x"], on["accel_x"])


def test_zero_vibration_leaves_the_flight_as_it_was():
    a = _flight(0.0)
    b = qc.fly("hover", "nlpd", vehicle="iris", duration=0.4, seed=3, sensors=Sensors(imu=Imu(rate=250.0)))
    assert a.equals(b.to_pandas())
    assert Imu().vibration == 0.0 and Imu().row().size == 14


def test_a_strong_vibration_raises_the_estimate_error():
    """30 m/s^2 a rotor (Flight Review's red: above g): the filter, told the datasheet's noise only,
    loses velocity accuracy and its velocity NEES rises (the vibration is noise it does not model)."""
    sensors = {k: PRESETS[k]["typical"] for k in ("gps", "baro", "mag")}
    imu = PRESETS["imu"]["bmi088_1khz"]
    runs = []
    for vibration in (0.0, 30.0):
        shaken = Sensors(imu=dataclasses.replace(imu, vibration=vibration), **sensors)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            r = qc.fly("hover", "nlpd", vehicle="iris", sensors=shaken, estimator=Ekf(), duration=4.0, n=4, seed=1)
        assert r.ok.all()
        d = r.to_pandas()
        error = d[["vx_est", "vy_est", "vz_est"]].to_numpy() - d[["vx", "vy", "vz"]].to_numpy()
        runs.append((np.sqrt(np.mean(error**2)), r.metrics()["nees_velocity"].mean(), d["accel_x"].std()))
    (v0, nees0, a0), (v1, nees1, a1) = runs
    assert a1 > 100.0 * a0  # the accelerometer shaken
    assert v1 > 1.15 * v0 and nees1 > 1.3 * nees0, runs


def test_the_paper_plant_refuses_a_vibration_in_one_line():
    with pytest.raises(InputError) as e:
        qc.fly("hover", "nlpd", duration=0.1, sensors=Sensors(imu=Imu(vibration=2.0)))
    text = str(e.value)
    assert "\n" not in text and "vibration" in text and text.startswith("fly() argument sensors: imu"), text
    qc.fly("hover", "nlpd", duration=0.1, sensors=Sensors(imu=Imu(vibration=0.0)))  # none: flown
    for call in (
        lambda: qc.compare("hover", controllers=["nlpd"], duration=0.1, sensors=Sensors(imu=Imu(vibration=2.0))),
        lambda: MonteCarloSpec("hover", population=Population(sensors=Sensors(imu=Imu(vibration=2.0)))),
        lambda: QuadVectorEnv(1, controller="nlpd", mission="hover", sensors=Sensors(imu=Imu(vibration=2.0))),
    ):
        with pytest.raises(InputError) as e:
            call()
        assert "\n" not in str(e.value) and "'vibration'" in str(e.value), str(e.value)


def test_a_chunked_flight_reads_the_same_vibration(monkeypatch):
    """The rotors' angles and speeds carried in the observer's memory from one kernel call to the next."""
    shaken = Sensors(imu=Imu(rate=250.0, vibration=5.0), gps=PRESETS["gps"]["typical"])
    kw = dict(vehicle="iris", sensors=shaken, estimator=Ekf(), duration=1.0, seed=2, n=2)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        whole = qc.fly("hover", "nlpd", **kw).decimate(10)  # one kernel call
        monkeypatch.setattr("quadcruise.sim.chunked.CHUNK_VEHICLE_STEPS", 2 * 333)  # chunks of 333 periods
        chunked = qc.fly("hover", "nlpd", log_every=10, **kw)
    for name in ("states", "observations"):
        np.testing.assert_array_equal(getattr(whole, name), getattr(chunked, name), err_msg=name)


def test_a_negative_vibration_is_refused():
    with pytest.raises(InputError, match="vibration"):
        Imu(vibration=-1.0)


def test_a_scenario_sensors_table_takes_the_vibration():
    from quadcruise.workflows.scenario_onboard import sensors_from_spec

    assert sensors_from_spec({"imu": {"preset": "bmi088_1khz", "vibration": 10.0}}).imu.vibration == 10.0
    with pytest.raises(InputError, match="imu field 'vibration'"):
        sensors_from_spec({"imu": {"preset": "bmi088_1khz", "vibration": -1.0}})
