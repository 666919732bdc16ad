"""The estimator everywhere else (issue 35 item 3): ``compare``, ``montecarlo`` (sensor models and
their spreads in a population), ``tune`` and the gym, each on the EKF's estimate when asked, checked
against an independent path (the flight's own truth and estimate columns, a vehicle flown alone
with the sensors its row says it drew, the same environment observing the truth), and bad input
refused in one line with exit 2 before any work."""

from __future__ import annotations

import dataclasses
import json
import warnings

import numpy as np
import pytest
from click.testing import CliRunner

import quadcruise as qc
from quadcruise.cli import main
from quadcruise.disturbances import SensorNoise
from quadcruise.errors import InputError
from quadcruise.estimation import Ekf, Sensors
from quadcruise.montecarlo import Population, montecarlo
from quadcruise.montecarlo.population import N_DRAWS
from quadcruise.montecarlo.sensor_spread import GPS_FIELDS, GPS_SLOT, IMU_FIELDS, IMU_SLOT
from quadcruise.montecarlo.spec import MonteCarloSpec
from quadcruise.workflows.compare import compare

TYPICAL = Sensors.typical()


def run(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


def one_line_exit_2(res, message):
    assert res.exit_code == 2, res.output
    lines = res.output.strip().splitlines()
    assert len(lines) == 1 and message in lines[0] and "Traceback" not in res.output, res.output


def position_rmse(result, i=0):
    frame = result.to_pandas(vehicle=i)
    d = frame[["x", "y", "z"]].to_numpy() - frame[["x_est", "y_est", "z_est"]].to_numpy()
    d = d[np.isfinite(d).all(axis=1)]
    return float(np.sqrt(np.mean(np.sum(d**2, axis=1))))


# --- compare --------------------------------------------------------------------------------
def test_compare_on_the_estimate_says_so_and_measures_it():
    kw = dict(duration=2.0, log_every=10, seed=3)
    on_estimate = compare("hover", ["nlpd", "se3"], sensors=TYPICAL, estimator=Ekf(), **kw)
    on_truth = compare("hover", ["nlpd", "se3"], **kw)
    table, truth = on_estimate.metrics(), on_truth.metrics()
    assert "controllers flew on the estimate: ekf on imu, gps, baro, mag" in on_estimate.text()
    assert on_estimate.to_dict()["flown_on"] == on_estimate.flown_on()
    assert "estimate" not in on_truth.text() and "estimate_position_rmse_m" not in truth.columns
    for label, res in on_estimate.results.items():  # the table's estimate error, from the traces
        assert table.loc[label, "estimate_position_rmse_m"] == pytest.approx(position_rmse(res), rel=1e-9)
        assert 0.01 < table.loc[label, "estimate_position_rmse_m"] < 1.0
        # hovering on the truth holds the point; on the estimate it wanders with the filter
        assert table.loc[label, "rmse_m"] > 10 * truth.loc[label, "rmse_m"]


def test_compare_refuses_an_estimator_without_its_sensors_before_any_flight():
    calls = []
    with pytest.raises(InputError, match=r"compare\(\) argument estimator: ekf needs the sensor 'gps'"):
        compare("hover", ["nlpd"], sensors=Sensors.typical(("imu",)), estimator=Ekf(), duration=1.0,
                progress=lambda done, total: calls.append(done))  # fmt: skip
    assert calls == []


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--sensors", "imu", "--estimator", "ekf"], "needs the sensor 'gps'"),
        (["--sensors", "imu,radar"], "--sensors: unknown sensor 'radar'"),
        (["--sensors", "imu,gps", "--estimator", "ukf"], "unknown estimator 'ukf'"),
        (["--sensors", "imu,gps", "--estimator", "ekf", "--dt", "0.003"], "imu rate 250 Hz does not divide"),
    ],
)
def test_compare_cli_bad_sensor_options_are_one_line_and_exit_2(tmp_path, args, message):
    out = tmp_path / "cmp"
    one_line_exit_2(run("compare", "hover", "--controllers", "nlpd", "--duration", "1", "--out", out, *args), message)
    assert not out.exists()


def test_compare_cli_on_the_estimate_writes_it_down(tmp_path):
    out = tmp_path / "cmp"
    res = run("compare", "hover", "--controllers", "nlpd,se3", "--duration", "1", "--sensors", "imu,gps",
              "--estimator", "ekf", "--out", out)  # fmt: skip
    assert res.exit_code == 0, res.output
    assert "controllers flew on the estimate: ekf on imu, gps" in res.output
    assert "estimate_position_rmse_m" in res.output
    scenario = (out / "scenario.toml").read_text()
    assert "[sensors" in scenario and "[estimator]" in scenario and 'kind = "ekf"' in scenario
    assert "flew on the estimate" in json.loads((out / "quadcruise.json").read_text())["flown_on"]
    again = run("compare", out / "scenario.toml", "--duration", "1")  # the scenario flies it again
    assert again.exit_code == 0 and "controllers flew on the estimate" in again.output, again.output


# --- a population's sensors -----------------------------------------------------------------
def test_sensor_spreads_draw_from_the_spare_slots_and_move_no_other_draw():
    plain = Population(mass_spread=0.1, sensors=TYPICAL)
    spread = dataclasses.replace(plain, imu_noise_spread=0.2, gps_noise_spread=0.1)
    z = spread.unit_draws(7, 0, 6)
    assert z.shape == (6, N_DRAWS)
    a, b = (p.draw(7, 0, 6, qc.Vehicle.paper()) for p in (plain, spread))
    np.testing.assert_array_equal(a.columns["m"], b.columns["m"])  # the vehicles as they were
    np.testing.assert_array_equal(b.columns["imu_noise_factor"], 1.0 + 0.2 * z[:, IMU_SLOT])
    np.testing.assert_array_equal(b.columns["gps_noise_factor"], 1.0 + 0.1 * z[:, GPS_SLOT])
    assert a.sensors is TYPICAL and np.all(a.columns["imu_noise_factor"] == 1.0)
    for k, s in enumerate(b.sensors):
        for f in IMU_FIELDS:
            assert getattr(s.imu, f) == pytest.approx(getattr(TYPICAL.imu, f) * b.columns["imu_noise_factor"][k])
        for f in GPS_FIELDS:
            assert getattr(s.gps, f) == pytest.approx(getattr(TYPICAL.gps, f) * b.columns["gps_noise_factor"][k])
        assert s.baro == TYPICAL.baro and s.imu.rate == TYPICAL.imu.rate


@pytest.mark.parametrize(
    ("fields", "message"),
    [
        ({"imu_noise_spread": 0.1}, "population field 'imu_noise_spread' spreads the imu's noise"),
        ({"sensors": Sensors.typical(("imu",)), "gps_noise_spread": 0.1}, "carry no gps"),
        ({"sensors": TYPICAL, "noise": SensorNoise(position_std=0.1)}, "'sensors' and 'noise' both"),
        ({"sensors": Sensors.typical(("imu", "baro")), "estimator": Ekf()}, "needs the sensor 'gps'"),
        ({"estimator": Ekf()}, "needs the sensor 'imu'"),
        ({"sensors": TYPICAL, "imu_noise_spread": 0.5}, "'imu_noise_spread' = 0.5 is too large"),
        ({"sensors": TYPICAL, "gps_noise_spread": -0.1}, "'gps_noise_spread' must be a number >= 0"),
        ({"sensors": "imu,gps"}, "population field 'sensors' must be a Sensors"),
    ],
)
def test_bad_population_sensors_are_refused_in_one_line(fields, message):
    with pytest.raises(InputError, match=None) as err:
        Population(**fields)
    assert message in str(err.value) and "\n" not in str(err.value)


def test_a_sweep_refuses_a_sensor_rate_its_dt_cannot_sample_before_any_flight():
    with pytest.raises(InputError, match="imu rate 250 Hz does not divide the control rate"):
        MonteCarloSpec("hover", population=Population(sensors=TYPICAL, estimator=Ekf()), dt=0.003, duration=0.9)


def test_a_sweep_row_is_the_vehicle_flown_alone_on_the_sensors_it_drew():
    pop = Population(sensors=TYPICAL, estimator=Ekf(), imu_noise_spread=0.3, gps_noise_spread=0.3)
    sweep = montecarlo("hover", "nlpd", pop, 3, 2, duration=2.0, scheduler="none")
    assert sweep.table["estimate_position_rmse_m"].notna().all()
    assert sweep.table["imu_noise_factor"].nunique() == 3
    row = sweep.table.iloc[2]
    imu, gps = TYPICAL.imu, TYPICAL.gps
    own = Sensors(
        imu=dataclasses.replace(imu, **{f: getattr(imu, f) * row["imu_noise_factor"] for f in IMU_FIELDS}),
        gps=dataclasses.replace(gps, **{f: getattr(gps, f) * row["gps_noise_factor"] for f in GPS_FIELDS}),
        baro=TYPICAL.baro, mag=TYPICAL.mag,
    )  # fmt: skip
    matched = Ekf(noise=Ekf().settings(TYPICAL, qc.Vehicle.paper().g))  # the filter of the datasheet's sensors
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        alone = qc.fly("hover", "nlpd", sensors=own, estimator=matched, seed=2, first_vehicle=2, duration=2.0,
                       log_every=sweep.spec.log_every)  # fmt: skip
    m = alone.metrics().iloc[0]
    for name in ("estimate_position_rmse_m", "estimate_attitude_rmse_deg", "nees_position", "rmse_m"):
        assert row[name] == pytest.approx(m[name], rel=1e-9), name
    summary = sweep.summary_data()
    assert set(summary["consistency"]) == {"nees_position", "nees_velocity", "nees_attitude"}
    assert "estimate_position_rmse_m" in summary["metrics"]
    truth = montecarlo("hover", "nlpd", Population(offset=0.1), 2, 2, duration=1.0, scheduler="none")
    assert (
        "consistency" not in truth.summary_data() and "estimate_position_rmse_m" not in truth.summary_data()["metrics"]
    )


def test_montecarlo_cli_on_the_estimate_and_its_scenario(tmp_path):
    res = run("montecarlo", "--mission", "hover", "--sensors", "imu,gps,baro,mag", "--estimator", "ekf",
              "--imu-noise-spread", "0.2", "-n", "3", "--duration", "1", "--scheduler", "none", "--quiet",
              "--out", tmp_path / "mc")  # fmt: skip
    assert res.exit_code == 0, res.output
    assert "filter consistency" in res.output and "estimate_position_rmse_m" in res.output
    scenario = (tmp_path / "mc" / "scenario.toml").read_text()
    assert "[sensors" in scenario and "imu_noise_spread = 0.2" in scenario and 'kind = "ekf"' in scenario
    again = run("montecarlo", "--scenario", tmp_path / "mc" / "scenario.toml", "--scheduler", "none", "--quiet")
    assert again.exit_code == 0, again.output
    assert [line for line in again.output.splitlines() if "nees_position" in line] == [
        line for line in res.output.splitlines() if "nees_position" in line
    ]


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--imu-noise-spread", "0.1"], "spreads the imu's noise; the population's sensors carry no imu"),
        (["--sensors", "imu", "--estimator", "ekf"], "needs the sensor 'gps'"),
        (["--sensors", "imu,gps", "--noise", "position=0.1"], "'sensors' and 'noise' both"),
        (["--sensors", "imu,gps", "--dt", "0.003", "--duration", "0.9"], "imu rate 250 Hz does not divide"),
    ],
)
def test_montecarlo_cli_bad_sensor_options_are_one_line_and_exit_2(tmp_path, args, message):
    out = tmp_path / "mc"
    res = run("montecarlo", "--mission", "hover", "-n", "2", "--duration", "1", "--scheduler", "none", "--quiet",
              "--out", out, *args)  # fmt: skip
    one_line_exit_2(res, message)
    assert not out.exists()


# --- tune -----------------------------------------------------------------------------------
def test_tune_on_the_estimate_flies_its_candidates_on_it(tmp_path):
    out = tmp_path / "tuned"
    res = run("tune", "step", "-m", "time=0.5", "--gains", "position.kp", "--target", "rise_time_s=1.2+-0.3",
              "--budget", "1", "--popsize", "5", "--duration", "4", "--sensors", "imu,gps", "--estimator", "ekf",
              "--out", out)  # fmt: skip
    assert res.exit_code in (0, 1), res.output
    scenario = (out / "scenario.toml").read_text()
    assert "[sensors" in scenario and 'kind = "ekf"' in scenario
    assert "--sensors imu,gps --estimator ekf" in scenario  # the command that tunes it again
    flown = run("fly", out / "scenario.toml")  # the tuned gains flown on the estimate again
    assert flown.exit_code in (0, 1) and "estimate_position_rmse_m" in flown.output, flown.output


def test_tune_cli_refuses_an_estimator_without_its_sensors(tmp_path):
    out = tmp_path / "tuned"
    res = run("tune", "step", "--gains", "position.kp", "--target", "rise_time_s=1.2", "--estimator", "ekf",
              "--out", out)  # fmt: skip
    one_line_exit_2(res, "--estimator ekf needs the sensor 'imu'")
    assert not out.exists()


# --- fly's figure and report ----------------------------------------------------------------
def test_the_estimate_figure_draws_the_truth_and_the_estimate_of_the_traces():
    from quadcruise.plots.estimate import plot_estimate

    r = qc.fly("circle", sensors=TYPICAL, estimator=Ekf(), duration=2.0, log_every=10, seed=4)
    fig = plot_estimate(r)
    frame = r.to_pandas()
    lines = fig.axes[0].get_lines()  # x solid, x dashed, y solid, ...
    np.testing.assert_array_equal(lines[0].get_ydata(), frame["x"].to_numpy())
    np.testing.assert_array_equal(lines[1].get_ydata(), frame["x_est"].to_numpy())
    np.testing.assert_array_equal(fig.axes[1].get_lines()[2].get_ydata(), (frame["z"] - frame["z_est"]).to_numpy())
    assert f"{r.metrics()['estimate_position_rmse_m'].iloc[0]:.3g} m" in fig.get_suptitle()


def test_fly_writes_the_estimate_figure_and_report_section_only_on_an_estimator(tmp_path):
    on = run("fly", "hover", "--duration", "1", "--sensors", "imu,gps", "--estimator", "ekf",
             "--out", tmp_path / "on", "--report", tmp_path / "on.html")  # fmt: skip
    off = run("fly", "hover", "--duration", "1", "--sensors", "imu,gps",
              "--out", tmp_path / "off", "--report", tmp_path / "off.html")  # fmt: skip
    assert on.exit_code == 0 and off.exit_code == 0, on.output + off.output
    assert (tmp_path / "on" / "estimate.png").stat().st_size > 10_000
    assert not (tmp_path / "off" / "estimate.png").exists()  # sensors logged, the controller on the truth
    assert "estimate the controller flew on (imu, gps)" in (tmp_path / "on.html").read_text()
    assert "estimate the controller flew on" not in (tmp_path / "off.html").read_text()


def test_estimator_none_overrides_a_scenarios_in_montecarlo_and_tune(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text('[mission]\nkind = "hover"\n[simulation]\nduration = 1.0\n[sensors]\nimu = "typical"\n'
                    'gps = "typical"\n[estimator]\nkind = "ekf"\n[montecarlo]\nn = 2\n')  # fmt: skip
    on = run("montecarlo", "--scenario", path, "--scheduler", "none", "--quiet")
    off = run("montecarlo", "--scenario", path, "--scheduler", "none", "--quiet", "--estimator", "none")
    assert on.exit_code == 0 and off.exit_code == 0, on.output + off.output
    assert "filter consistency" in on.output and "filter consistency" not in off.output
    out = tmp_path / "tuned"
    res = run("tune", path, "--gains", "position.kp", "--minimize", "rmse_m", "--budget", "1", "--popsize", "5",
              "--estimator", "none", "--out", out)  # fmt: skip
    assert res.exit_code in (0, 1), res.output
    assert 'kind = "none"' in (out / "scenario.toml").read_text()  # sensors logged, the truth flown


def test_a_rotor_plant_sweep_flies_on_its_spread_sensors():
    from quadcruise.estimation.stage import PRESETS

    sensors = dataclasses.replace(TYPICAL, imu=PRESETS["imu"]["bmi088_1khz"])  # the iris needs a 1 kHz IMU
    pop = Population(mass_spread=0.05, sensors=sensors, estimator=Ekf(), imu_noise_spread=0.2)
    sweep = montecarlo("hover", "nlpd", pop, 3, 0, vehicle="iris", duration=2.0, scheduler="none")
    tab = sweep.table
    assert (tab["status"] == 0).all() and tab["imu_noise_factor"].nunique() == 3  # every flight finished
    assert tab["estimate_position_rmse_m"].between(0.01, 1.0).all()
    assert sweep.summary_data()["consistency"]["nees_position"]["flights"] == 3


def test_compare_population_flies_on_the_estimate_too(tmp_path):
    res = run("compare", "hover", "--controllers", "nlpd,se3", "--duration", "1", "--sensors", "imu,gps",
              "--estimator", "ekf", "--population", "3", "--out", tmp_path / "cmp")  # fmt: skip
    assert res.exit_code == 0, res.output
    assert "estimate_position_rmse_m p50" in res.output
    table = (tmp_path / "cmp" / "population.csv").read_text()
    assert "estimate_position_rmse_m p50" in table.splitlines()[0]
    assert "[compare.population]" in (tmp_path / "cmp" / "scenario.toml").read_text()
