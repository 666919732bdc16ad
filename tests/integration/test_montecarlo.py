"""Monte Carlo sweeps: determinism whatever the chunking, replay of one case, metrics equal
to flight_metrics, a real Dask LocalCluster (with a worker killed mid-run), resume after an
interruption, and bad input."""

import dataclasses
import json
import os
import signal
import warnings

import numpy as np
import pandas as pd
import pytest

from quadcruise.cli.montecarlo import montecarlo_command
from quadcruise.disturbances import ConstantWind, Environment, SensorNoise, Turbulence, with_drag
from quadcruise.errors import InputError, SimulationError
from quadcruise.metrics import flight_metrics
from quadcruise.model.vehicle import Vehicle
from quadcruise.montecarlo import MonteCarloSpec, Population, Requirement, montecarlo, montecarlo_case, replay_case
from quadcruise.montecarlo.chunk import fly_chunk, sweep_metrics
from quadcruise.montecarlo.schema import COLUMNS

POP = Population(
    mass_spread=0.15, inertia_spread=0.1, thrust_spread=0.1, bandwidth_spread=0.1, yaw_arm_spread=0.1, offset=0.2
)
# and the world: turbulence and sensor noise draw from the engine's per-vehicle streams
WORLD = dataclasses.replace(
    POP,
    environment=Environment(turbulence=Turbulence(intensity="light", altitude=5.0)),
    wind_spread=0.5,
    noise=SensorNoise(position_std=0.005, rate_std=0.01, delay=0.002),
)
with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    DRAG = with_drag(Vehicle.paper())
FAST = dict(duration=3.0, dt=2e-3)  # short flights: 1,500 periods
FIGURES = ("histograms.png", "envelope.png")


def sweep(n=24, **kw):
    """A small in-process sweep of the circle, in turbulence, with sensor noise."""
    options = dict(seed=1, scheduler="none", chunk_size=7, vehicle=DRAG, **FAST)
    options.update(kw)
    return montecarlo("circle", "nlpd", options.pop("population", WORLD), n, **options)


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """The in-process sweep every distributed run must equal, written to a folder."""
    out = tmp_path_factory.mktemp("ref") / "sweep"
    return sweep(out=out), out


@pytest.fixture(scope="module")
def cluster():
    from distributed import LocalCluster

    with LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0", env={"NUMBA_NUM_THREADS": "1"}
    ) as c:
        yield c


def same_outputs(a, b):
    """Two result folders hold the same table, summary and figures (byte for byte)."""
    pd.testing.assert_frame_equal(pd.read_csv(a / "flights.csv"), pd.read_csv(b / "flights.csv"), check_exact=True)
    sa, sb = (json.loads((p / "summary.json").read_text()) for p in (a, b))
    sa.pop("info"), sb.pop("info")
    assert sa == sb
    for name in FIGURES:
        assert (a / name).read_bytes() == (b / name).read_bytes(), name


def same_row(a: dict, b: dict) -> bool:
    """Equal keys and values (NaN equal to NaN)."""
    return a.keys() == b.keys() and all(a[k] == b[k] or (a[k] != a[k] and b[k] != b[k]) for k in a)


# --- population ---------------------------------------------------------------------------
def test_draws_depend_on_seed_and_index_only():
    v = Vehicle.paper()
    whole = POP.draw(seed=5, first=0, count=10, nominal=v)
    part = POP.draw(seed=5, first=6, count=3, nominal=v)
    for name, col in part.columns.items():
        assert np.array_equal(col, whole.columns[name][6:9]), name
    # one spread changes only its own quantity
    more = dataclasses.replace(POP, mass_spread=0.05).draw(5, 0, 10, v)
    assert not np.array_equal(more.columns["m"], whole.columns["m"])
    for name in ("Jxx", "K", "omega", "dx0"):
        assert np.array_equal(more.columns[name], whole.columns[name])
    assert not np.array_equal(POP.draw(6, 0, 10, v).columns["m"], whole.columns["m"])
    # normal draws are truncated at 3 sigma: every value positive and within the band
    m = Population(mass_spread=0.3).draw(0, 0, 2000, v).columns["m"]
    assert m.min() >= v.m * (1 - 0.9) - 1e-12 and m.max() <= v.m * (1 + 0.9) + 1e-12
    u = Population(mass_spread=0.1, distribution="uniform").draw(0, 0, 4000, v).columns["m"]
    assert abs(np.std(u / v.m) - 0.1) < 0.005 and np.all(np.abs(u / v.m - 1) <= 0.1 * 3**0.5)


def numpy_normals(seed: int, i: int):
    """numpy's generator of vehicle i's draws, SeedSequence([seed, i], spawn_key=(1,))."""
    return np.random.default_rng(np.random.SeedSequence([seed, i], spawn_key=(1,)))


def truncated_draws(seed: int, i: int) -> np.ndarray:
    """The documented draws of vehicle i, independently: 16 standard normals of numpy's
    generator, each beyond 3 sigma replaced in order by the stream's next draws within it."""
    g = numpy_normals(seed, i)
    z = g.standard_normal(16)
    for k in np.flatnonzero(np.abs(z) > 3.0):
        while abs(v := g.standard_normal()) > 3.0:
            pass
        z[k] = v
    return z


def test_normal_draws_are_truncated_not_clipped():
    """A clip at 3 sigma gave each of the 0.13 % of vehicles beyond it the same mass: a 10,000-flight
    sweep's "worst 5" were five identical rows (m = 1.3 x nominal). Truncated: every vehicle its own."""
    pop = Population(mass_spread=0.1)
    z = pop.unit_draws(1, 0, 10_000)
    assert np.abs(z).max() <= 3.0 and len(np.unique(z[:, 0])) == 10_000
    m = pop.draw(1, 0, 10_000, Vehicle.paper()).columns["m"]
    assert len(np.unique(m)) == 10_000
    past = [i for i in range(300) if np.abs(numpy_normals(1, i).standard_normal(16)).max() > 3.0]
    assert len(past) >= 3  # vehicles with a draw beyond 3 sigma, drawn again
    for i in [*past, 0, 1, 299]:
        np.testing.assert_array_equal(z[i], truncated_draws(1, i), err_msg=str(i))
        clipped = np.clip(numpy_normals(1, i).standard_normal(16), -3.0, 3.0)  # the old rule
        assert np.array_equal(clipped, z[i]) == (i not in past)


@pytest.mark.parametrize(
    "kw, words",
    [
        (dict(mass_spread=-0.1), "mass_spread"),
        (dict(inertia_spread=0.4), "too large"),
        (dict(thrust_spread=0.6, distribution="uniform"), "too large"),
        (dict(offset=float("nan")), "offset"),
        (dict(distribution="cauchy"), "distribution"),
        (dict(environment=Environment(wind=ConstantWind(velocity=([1.0, 2.0], 0.0, 0.0)))), "same for every vehicle"),
    ],
)
def test_population_rejects_bad_values(kw, words):
    with pytest.raises(InputError, match=words) as err:
        Population(**kw)
    assert "\n" not in str(err.value)


# --- determinism, cases, metrics ------------------------------------------------------------
def test_table_does_not_depend_on_chunking(reference):
    res = reference[0]
    other = sweep(chunk_size=25)
    pd.testing.assert_frame_equal(res.table, other.table, check_exact=True)
    assert res.table["vehicle"].tolist() == list(range(24))
    assert list(res.table.columns[: len(COLUMNS)]) == list(COLUMNS)
    assert not sweep(seed=2).table["m"].equals(res.table["m"])
    # memory stays bounded: paths of the first max_traces vehicles and of the first
    # max_failure_traces failed ones (3 s is mostly too short to settle into 2 %)
    small = sweep(max_traces=5, max_failure_traces=3, requirements={"settling_time_s": ("<=", 2.5)})
    failed = small.table.query("failure > 0 and vehicle >= 5")["vehicle"].tolist()
    assert len(failed) > 3
    assert small.traces.vehicle.tolist() == [0, 1, 2, 3, 4] + failed[:3]
    assert small.traces.sample.tolist() == [True] * 5 + [False] * 3


def test_a_case_flown_alone_equals_its_row(reference):
    res = reference[0]
    worst = res.worst(3)
    assert list(worst.columns[:2]) == ["vehicle", "seed"] and (worst["seed"] == 1).all()
    for i in (int(worst["vehicle"][0]), 17):
        case = replay_case(res, i)
        assert same_row(case.row, res.table.iloc[i].to_dict()), i
    full = montecarlo_case(res.spec, 3, log_every=1)  # every period, for a close look
    assert full.result.t.size == res.spec.periods + 1 and same_row(full.row, res.table.iloc[3].to_dict())


def test_a_case_and_fly_of_the_same_vehicle_give_one_status_and_time():
    """One rule for a flight's status: montecarlo --case K, a sweep's row and fly of the same vehicle alone
    (its log every period, the sweep's every 10 ms) say the same status at the same instant; off track
    (heavy vehicles sag) and finished alike."""
    import quadcruise as qc
    from quadcruise.montecarlo.output import case_text
    from quadcruise.sim.status import ExitStatus

    spec = MonteCarloSpec("circle", population=Population(mass_spread=0.1), seed=1)
    seen = set()
    for i in (576, 1):  # of a 2,000-flight sweep of seed 1: 576 (m = 4.50 kg) sags off track, 1 flies
        case = montecarlo_case(spec, i)
        alone = qc.fly("circle", vehicle=Vehicle.paper().replace(m=case.row["m"]), controller_vehicle=Vehicle.paper())
        coarse = qc.fly(
            "circle", vehicle=Vehicle.paper().replace(m=case.row["m"]), controller_vehicle=Vehicle.paper(), log_every=10
        )
        assert case.result.meta["log_every"] == 10 and alone.meta["log_every"] == 1
        for other in (case.result, coarse):
            assert other.status[0] == alone.status[0] and other.t_stop[0] == alone.t_stop[0], (i, other.status_text())
        assert case.row["status"] == alone.status[0] and case.row["stop_time_s"] == alone.t_stop[0]
        assert alone.status_text(0) in case_text(case, 1)
        seen.add(ExitStatus(int(alone.status[0])))
        assert case.row["reason"] == ("lost track" if alone.status[0] == ExitStatus.OFF_TRACK else "ok")
    assert seen == {ExitStatus.OFF_TRACK, ExitStatus.FINISHED}


def test_sweep_metrics_equal_flight_metrics():
    for mission in ("circle", "step"):
        spec = MonteCarloSpec(mission, population=POP, seed=3, duration=4.0, dt=2e-3)
        res, _ = fly_chunk(spec, 0, 6)
        # vehicle 2 "diverged" half way: its metrics are NaN in both
        states = res.states.copy()
        states[2, states.shape[1] // 2 :] = np.nan
        res = dataclasses.replace(res, states=states, status=np.where(np.arange(6) == 2, 2, res.status))
        fast, slow = sweep_metrics(res, spec), flight_metrics(res)
        kept = ~fast["lost_track"]  # the sweep judged the others off track: no transient to show
        assert np.isnan(fast["rise_time_s"][~kept]).all() and np.isfinite(fast["rmse_m"][~kept]).all()
        for k in (
            "rmse_m",
            "max_error_m",
            "steady_rmse_m",
            "steady_max_error_m",
            "rise_time_s",
            "settling_time_s",
            "settling_time_5pct_s",
            "overshoot_pct",
            "peak_time_s",
            "effort",
            "duty_clipped_s",
            "controller_limited_s",
        ):
            np.testing.assert_allclose(
                fast[k][kept], slow[k].to_numpy(dtype=float)[kept], rtol=1e-12, atol=1e-15, err_msg=f"{mission} {k}"
            )
        assert np.isnan(fast["rmse_m"][2]) and fast["diverged"].tolist() == [False, False, True, False, False, False]
        axes = [{"x": 0, "y": 1, "z": 2, "xyz": 3}.get(a, -1) if isinstance(a, str) else -1 for a in slow["axis"]]
        assert fast["transient_axis"].tolist() == axes


# --- failures and requirements ---------------------------------------------------------------
def test_not_settling_within_2pct_is_a_metric_not_a_failure():
    """A 6 s circle has not converged onto its steady lag within 2 % by half its length (the
    entry settles there in about 4.2 s): marked, not failed; every one tracks within decimetres."""
    res = montecarlo(
        "circle", "nlpd", Population(mass_spread=0.05), 24, seed=1, scheduler="none", settle_band=0.02, duration=6.0
    )
    tab = res.table
    assert tab["not_settled"].mean() > 0.8
    assert (tab["failure"] == 0).all() and (tab["reason"] == "ok").all()
    assert tab["steady_max_error_m"].max() < 0.5 and tab["final_error_m"].max() < 0.5
    s = res.summary()
    assert s["failures"]["count"] == 0 and s["not_settled"]["count"] == tab["not_settled"].sum()
    assert list(s["failures"]["by_reason"]) == ["diverged", "lost track", "saturated", "failed a requirement"]
    assert "not settled within 2 % (a metric, not a failure)" in str(s)


def test_lost_track_is_the_error_after_the_transient_beyond_a_bound():
    spec = MonteCarloSpec("circle", population=Population(mass_spread=0.1), seed=1)
    assert spec.max_track_error_m == 1.0 and spec.to_dict()["max_track_error_m"] == 1.0
    res = montecarlo("circle", "nlpd", Population(mass_spread=0.1), 24, seed=1, scheduler="none", max_track_error_m=0.3)
    tab = res.table
    lost = tab["lost_track"]
    assert 0 < lost.sum() < len(tab) and (tab.loc[lost, "reason"] == "lost track").all()
    # the kept flights' steady window (the last half) lies after the transient, where the bound held;
    # the lost ones have no steady state to show
    assert (tab.loc[~lost, "steady_max_error_m"] <= 0.3).all() and tab.loc[lost, "steady_max_error_m"].isna().all()
    assert res.spec.max_altitude_error_m == 0.3  # a bound given bounds the altitude too
    assert "lost track" in res.summary_text() and "> 0.3 m" in res.summary_text()
    # the histograms count the flights the quantiles are over (not the lost ones)
    fig = res.plot_histograms(["rmse_m", "effort"])
    rmse, effort = fig.axes[0], fig.axes[1]
    assert sum(p.get_height() for p in rmse.patches) == res.summary()["metrics"]["rmse_m"]["count"] == (~lost).sum()
    kept = tab.loc[~lost, "effort"]  # and each axis spans its own data
    assert effort.get_xlim()[0] <= kept.min() and effort.get_xlim()[1] >= kept.max()
    assert effort.get_xlim()[1] - effort.get_xlim()[0] < 2 * (kept.max() - kept.min())
    with pytest.raises(InputError, match="max_track_error_m"):
        MonteCarloSpec("circle", max_track_error_m=-1.0)


def test_a_requirement_that_fails_is_counted_and_shown(tmp_path):
    req = "steady_max_error_m<=0.2"
    res = montecarlo(
        "circle",
        "nlpd",
        Population(mass_spread=0.1),
        24,
        seed=1,
        scheduler="none",
        requirements=[Requirement("steady_max_error_m", "<=", 0.2)],
        out=tmp_path / "mc",
    )
    tab = res.table
    missed = ~(tab["steady_max_error_m"] <= 0.2)  # a lost flight (no steady metric) misses it too
    lost = tab["lost_track"]
    assert 0 < (missed & ~lost).sum() and missed.sum() < len(tab)
    assert tab["failed_requirement"].tolist() == missed.tolist()
    assert (tab.loc[missed & ~lost, "reason"] == "failed a requirement").all()
    assert (tab.loc[lost, "reason"] == "lost track").all() and (tab.loc[~missed, "failure"] == 0).all()
    s = res.summary()
    assert s["requirements"] == [{"requirement": req, "failed": int(missed.sum()), "rate": missed.mean()}]
    assert s["failures"]["by_reason"]["failed a requirement"]["count"] == (missed & ~lost).sum()
    assert f"requirement {req}: missed by {missed.sum()}" in str(s)
    report = (tmp_path / "mc" / "report.md").read_text()
    assert f"| `{req}` | {missed.sum()} |" in report
    assert json.loads((tmp_path / "mc" / "summary.json").read_text())["requirements"][0]["failed"] == missed.sum()
    # other criteria are another sweep: a folder of this one is not resumed with them
    with pytest.raises(InputError, match="different sweep"):
        montecarlo(
            "circle",
            "nlpd",
            Population(mass_spread=0.1),
            24,
            seed=1,
            scheduler="none",
            requirements={"steady_max_error_m": ("<=", 0.3)},
            out=tmp_path / "mc",
        )


def test_requirements_are_objects_kept_as_text_in_the_record():
    spec = MonteCarloSpec("circle", requirements={"rmse_m": ("<", 0.5), "overshoot_pct": (">=", 1)})
    assert spec.requirements == (Requirement("rmse_m", "<", 0.5), Requirement("overshoot_pct", ">=", 1.0))
    assert spec.to_dict()["requirements"] == ["rmse_m<0.5", "overshoot_pct>=1"]
    from quadcruise.montecarlo.scenario import parse_requirement

    odd = Requirement("rmse_m", "<=", 0.1 + 0.2)  # the text a scenario.toml keeps reads back to the same float
    assert odd.text == "rmse_m<=0.30000000000000004" and parse_requirement(odd.text) == odd
    one = MonteCarloSpec("circle", requirements=Requirement("rmse_m", "<", 0.5))
    assert one == MonteCarloSpec("circle", requirements=[Requirement("rmse_m", "<", 0.5)]) and one.hash() != spec.hash()
    with pytest.raises(TypeError, match=r"^MonteCarloSpec\(\) argument requirements must be Requirement objects"):
        MonteCarloSpec("circle", requirements="rmse_m < 0.5")  # text is the command line's and the scenario's
    with pytest.raises(TypeError, match=r"^montecarlo\(\) argument requirements\[0\] must be a Requirement"):
        montecarlo("hover", n=2, duration=0.5, scheduler="none", requirements=["rmse_m<0.5"])


@pytest.mark.parametrize(
    "text, words",
    [
        (
            "steady_max_error<=0.2",
            "unknown metric 'steady_max_error'; choose one of rmse_m, max_error_m, steady_rmse_m",
        ),
        ("rmse_m=<0.2", "expected METRIC<=VALUE"),
        ("rmse_m<=fast", "'fast' is not a finite number"),
    ],
)
def test_a_bad_requirement_is_refused_before_any_flight(tmp_path, text, words):
    from click.testing import CliRunner

    from quadcruise.cli import main

    out = tmp_path / "mc"
    res = CliRunner().invoke(
        main,
        [
            "montecarlo",
            "--n",
            "4",
            "--duration",
            "1",
            "--scheduler",
            "none",
            "--out",
            str(out),
            "--require",
            "rmse_m<1",
            "--require",
            text,
        ],
    )
    assert res.exit_code == 2, res.output
    assert words in res.output and f"requirement {text!r}" in res.output and len(res.output.strip().splitlines()) == 1
    assert not out.exists()
    scenario = tmp_path / "s.toml"  # the same text in a scenario's [montecarlo] table
    scenario.write_text(f'[mission]\nkind = "hover"\n[montecarlo]\nn = 4\nrequirements = ["rmse_m<1", "{text}"]\n')
    res = CliRunner().invoke(
        main, ["montecarlo", "--scenario", str(scenario), "--scheduler", "none", "--out", str(out)]
    )
    assert res.exit_code == 2 and len(res.output.strip().splitlines()) == 1, res.output
    assert f"{scenario}: [montecarlo] requirements: requirement {text!r}: " in res.output and words in res.output
    assert not out.exists()


def test_metrics_on_the_decimated_log_are_close_to_full_rate():
    spec = MonteCarloSpec("circle", population=POP, seed=2, duration=8.0)
    fast = sweep_metrics(fly_chunk(spec, 0, 5)[0], spec)  # 10 ms log
    full = flight_metrics(fly_chunk(spec, 0, 5, log_every=1)[0])  # every 1 ms period
    kept = ~fast["lost_track"]  # the others show no transient
    for k, tol in (("rmse_m", 1e-5), ("max_error_m", 1e-4)):
        np.testing.assert_allclose(fast[k], full[k].to_numpy(dtype=float), rtol=tol, err_msg=k)
    for k in ("rise_time_s", "settling_time_5pct_s"):  # crossings interpolated on the 10 ms log:
        np.testing.assert_allclose(
            fast[k][kept], full[k].to_numpy(dtype=float)[kept], atol=1e-3, err_msg=k
        )  # 1/10 of it


def test_the_world_acts_and_drag_is_added_with_a_warning():
    with pytest.warns(UserWarning, match="no drag"):
        spec = MonteCarloSpec("circle", population=WORLD, seed=1, **FAST)
    assert spec.vehicle.drag_quadratic > 0
    res = sweep(n=12)
    still = sweep(n=12, population=POP)
    assert res.table["wind_x"].std() > 0.2 and (still.table["wind_x"] == 0).all()
    assert not np.allclose(res.table["rmse_m"], still.table["rmse_m"])
    pd.testing.assert_frame_equal(res.table, sweep(n=12, chunk_size=12).table, check_exact=True)


@pytest.mark.dask
# --- Dask ---------------------------------------------------------------------------------
def test_local_cluster_equals_in_process(reference, tmp_path):
    ref, ref_out = reference
    res = sweep(scheduler="local", workers=2, out=tmp_path / "dask")
    assert "local Dask cluster of 2 processes" in res.info["scheduler"]
    pd.testing.assert_frame_equal(res.table, ref.table, check_exact=True)
    same_outputs(tmp_path / "dask", ref_out)


@pytest.mark.dask
def test_the_local_cluster_runs_with_its_quiet_settings():
    from quadcruise.montecarlo.sweep import LOCAL_CLUSTER_SETTINGS, _Dask

    runner = _Dask("local", 1, 10.0)
    try:
        got = runner.client.run(lambda: {k: __import__("dask").config.get(k) for k in LOCAL_CLUSTER_SETTINGS})
        stealing = runner.client.run_on_scheduler(lambda dask_scheduler: "stealing" in dask_scheduler.extensions)
    finally:
        runner.close()
    assert list(got.values()) == [LOCAL_CLUSTER_SETTINGS] and stealing is False


@pytest.mark.dask
def test_a_worker_killed_mid_run_costs_nothing(reference, cluster, tmp_path):
    from distributed import Client

    ref, ref_out = reference
    killed = []
    with Client(cluster.scheduler_address) as client:

        def held():
            """Chunks of this run on each worker: running, waiting there, or done and not yet fetched."""
            keys = {w: {k for k in ks if "quadcruise-chunk" in str(k)} for w, ks in client.processing().items()}
            for w, ks in client.has_what().items():
                keys.setdefault(w, set()).update(k for k in ks if "quadcruise-chunk" in str(k))
            return {w: len(ks) for w, ks in keys.items()}

        def kill_a_busy_worker(done, total):
            # after the first chunk, the other chunks in flight are on the workers (a fast machine may
            # have flown them all already: their results then wait in the workers' memory, and the
            # scheduler must fly them again when the worker dies)
            if killed or done == 0:
                return
            busy = held()
            victim = max(busy, key=busy.get) if busy else next(iter(client.nthreads()))
            pid = client.run(os.getpid, workers=[victim])[victim]
            os.kill(pid, signal.SIGKILL)
            killed.append((victim, busy.get(victim, 0)))

        res = sweep(
            scheduler=cluster.scheduler_address, out=tmp_path / "killed", chunk_size=3, progress=kill_a_busy_worker
        )
    assert killed and killed[0][1] >= 1, killed  # it died holding work
    assert res.table["vehicle"].tolist() == list(range(24))
    pd.testing.assert_frame_equal(res.table, ref.table, check_exact=True)
    same_outputs(tmp_path / "killed", ref_out)
    assert len(list((tmp_path / "killed" / "chunks").glob("*.npz"))) == 8


# --- on disk: resume, refusal -----------------------------------------------------------------
def test_an_interrupted_sweep_resumes_where_it_stopped(reference, tmp_path):
    ref, ref_out = reference
    out = tmp_path / "sweep"
    calls = []

    def stop_after_two_chunks(done, total):
        calls.append(done)
        if len(calls) == 3:  # the start, then two chunks
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        sweep(out=out, progress=stop_after_two_chunks)
    assert sorted(p.name for p in (out / "chunks").iterdir()) == ["chunk-000000000.npz", "chunk-000000007.npz"]
    assert json.loads((out / "quadcruise.json").read_text())["complete"] is False
    assert not (out / "flights.csv").exists()
    seen = []
    res = sweep(out=out, progress=lambda d, t: seen.append(d))
    assert res.info["resumed"] == 14 and res.info["flown"] == 10 and res.info["chunks_flown"] == 2
    assert seen[0] == 14 and seen[-1] == 24
    pd.testing.assert_frame_equal(res.table, ref.table, check_exact=True)
    same_outputs(out, ref_out)
    assert json.loads((out / "quadcruise.json").read_text())["complete"] is True
    again = sweep(out=out)  # complete: nothing to fly
    assert again.info["flown"] == 0 and again.info["resumed"] == 24


def test_a_folder_of_another_sweep_is_refused_unless_forced(reference, tmp_path):
    out = tmp_path / "sweep"
    sweep(n=7, out=out)
    with pytest.raises(InputError, match="different sweep"):
        sweep(n=7, out=out, seed=9)
    assert json.loads((out / "quadcruise.json").read_text())["seed"] == 1
    res = sweep(n=7, out=out, seed=9, force=True)
    assert res.info["flown"] == 7 and json.loads((out / "quadcruise.json").read_text())["seed"] == 9
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "notes.txt").write_text("keep")
    with pytest.raises(InputError, match="not empty"):
        sweep(n=7, out=tmp_path / "mine")
    assert (tmp_path / "mine" / "notes.txt").read_text() == "keep"


def test_auto_chunks_fit_the_memory_budget_and_split_evenly_over_threads():
    from quadcruise.montecarlo.sweep import CHUNK_BUDGET, auto_chunk_size

    spec = MonteCarloSpec("circle", "nlpd", Population(), seed=1, duration=60.0, dt=1e-3)
    alone = auto_chunk_size(spec, 10_000)
    assert alone * spec.log_bytes() <= CHUNK_BUDGET < (alone + 1) * spec.log_bytes()
    for threads in (2, 3, 4):
        size = auto_chunk_size(spec, 10_000, threads=threads)
        assert size % threads == 0 and alone - threads < size <= alone
    assert auto_chunk_size(spec, 8, parallel=2) == 1  # 4 chunks per worker
    assert auto_chunk_size(spec, 8, parallel=2, threads=2) == 1  # fewer vehicles than threads


def test_other_code_makes_another_sweep(reference, tmp_path, monkeypatch):
    """The spec hash covers the code: a folder flown by other code is not resumed, and a
    chunk from a worker running other code is refused, not mixed in."""
    import quadcruise.montecarlo.spec as mcspec
    from quadcruise.montecarlo.sweep import _Collector, run_chunk

    ref, ref_out = reference
    spec = ref.spec
    chunk = run_chunk(spec, 0, 2)
    monkeypatch.setattr(mcspec, "code_digest", lambda: "edited source tree")
    assert spec.hash() != str(chunk["hash"])
    with pytest.raises(SimulationError, match="other quadcruise code"):
        _Collector(spec, 2).add(chunk)
    with pytest.raises(InputError, match="different sweep"):
        sweep(out=ref_out)


# --- bad input ------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "kw, words",
    [
        (dict(mass_spread=-0.1), "mass_spread"),
        (dict(n=0), "number of flights"),
        (dict(wind="hurricane:3"), "unknown model 'hurricane'"),
        (dict(scheduler="tcp://127.0.0.1:9", connect_timeout=1.0), "cannot reach the Dask scheduler"),
        (dict(chunk_size="many"), "chunk-size"),
        (dict(noise="jitter=1"), "noise spec"),
    ],
)
def test_bad_input_is_one_line_and_writes_nothing(tmp_path, kw, words):
    out = tmp_path / "out"
    options = dict(
        n=4, seed=1, duration=1.0, mass_spread=0.1, scheduler="none", out=str(out), quiet=True, echo=lambda s: None
    )
    options.update(kw)
    with pytest.raises(InputError, match=words) as err:
        montecarlo_command(**options)
    assert "\n" not in str(err.value)
    assert not out.exists()


# --- command ----------------------------------------------------------------------------------
@pytest.mark.filterwarnings("ignore:the vehicle has no drag")
def test_command_prints_the_summary_and_replays_a_case(tmp_path):
    lines = []
    res = montecarlo_command(
        mission="hover",
        n=6,
        seed=4,
        duration=1.0,
        offset=0.05,
        mass_spread=0.1,
        wind="constant:1,0,0",
        scheduler="none",
        out=str(tmp_path / "mc"),
        quiet=True,
        echo=lines.append,
    )
    text = "\n".join(lines)
    assert "6 flights of nlpd on hover, seed 4" in text and "worst 5" in text
    for name in ("flights.csv", "summary.json", "worst.csv", "report.md", "quadcruise.json", *FIGURES):
        assert (tmp_path / "mc" / name).is_file(), name
    assert "## Worst flights" in (tmp_path / "mc" / "report.md").read_text()
    worst = int(res.worst(1)["vehicle"][0])
    same = dict(mission="hover", n=6, seed=4, duration=1.0, offset=0.05, mass_spread=0.1, wind="constant:1,0,0")
    case = montecarlo_command(**same, case=worst, out=str(tmp_path / "mc"), echo=lines.append)
    assert case.row["rmse_m"] == res.table["rmse_m"][worst]
    folder = tmp_path / "mc" / f"case-{worst:06d}"  # beside the sweep's results, which stay
    assert (folder / "flight.png").is_file() and (folder / "case.json").is_file()
    assert (tmp_path / "mc" / "flights.csv").is_file()
    with pytest.raises(InputError, match="other options"):
        montecarlo_command(**{**same, "seed": 5}, case=worst, out=str(tmp_path / "mc"), echo=lines.append)
