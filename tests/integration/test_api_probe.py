"""The Python API probed with wrong types and out-of-range values: every public function and
parameter class answers with one line naming the argument, a TypeError for a value of the wrong
kind and a ValueError for a value out of range (both InputErrors, so the command line prints
them and exits 2), before any work. And what must pass still passes."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import quadcruise as qc
from quadcruise.control import NLPD
from quadcruise.disturbances import ConstantWind, SensorNoise
from quadcruise.errors import ArgumentTypeError, InputError
from quadcruise.missions import Circle, Step
from quadcruise.montecarlo import Population, montecarlo
from quadcruise.sim.inputs import Limits
from quadcruise.tune import Bounds, Requirement, Target, tune
from quadcruise.workflows.analysis import linearize
from support.entry import run_entry

EXAMPLES = Path(__file__).parents[2] / "examples"
WRONG, BAD = TypeError, ValueError
RISE = {"rise_time_s": 1.0}


class PlainController:
    """The documented plug-in route with one step missed: ``function`` is not compiled."""

    name = "plain"

    @staticmethod
    def function(t, dt, x, ref, vp, gains, mem, cmd):
        cmd[:] = 0.5

    def gains(self):
        return np.zeros(1)

    def memory(self):
        return np.zeros(1)


def quick(**kw):
    """fly() keywords for a short flight (a probe that wrongly passes costs little)."""
    return {"duration": 0.1, **kw}


# (call, error type, words the one-line message must hold: the argument first)
CASES = {
    # fly: the cases of the issue
    "fly vehicle=3": (lambda: qc.fly("circle", vehicle=3), WRONG, ["vehicle", "Vehicle", "int 3"]),
    "fly vehicle=0": (lambda: qc.fly("circle", vehicle=0), WRONG, ["vehicle", "int 0"]),
    "fly the class Circle": (lambda: qc.fly(Circle), WRONG, ["mission", "the class Circle", "Circle()"]),
    "fly dt str": (lambda: qc.fly("step", dt="0.001"), WRONG, ["dt", "str '0.001'"]),
    "fly duration str": (lambda: qc.fly("step", duration="10"), WRONG, ["duration", "str '10'"]),
    "fly full_dynamics str": (lambda: qc.fly("step", full_dynamics="no"), WRONG, ["full_dynamics", "True or False"]),
    "fly full_dynamics 1": (lambda: qc.fly("step", full_dynamics=1), WRONG, ["full_dynamics"]),
    "fly seed 1.5": (
        lambda: qc.fly("step", **quick(seed=1.5, sensors=SensorNoise(position_std=0.01))),
        WRONG,
        ["seed", "whole number", "float 1.5"],
    ),
    "fly seed True": (lambda: qc.fly("step", **quick(seed=True)), WRONG, ["seed", "bool True"]),
    "fly seed -1": (lambda: qc.fly("step", **quick(seed=-1)), BAD, ["seed", ">= 0"]),
    "fly plain controller": (
        lambda: qc.fly("step", PlainController(), **quick()),
        WRONG,
        ["controller", "CONTROLLER_SIG", "plain Python function", "@njit(CONTROLLER_SIG"],
    ),
    "fly controller class": (lambda: qc.fly("step", NLPD), WRONG, ["controller", "the class NLPD", "NLPD()"]),
    "fly controller float": (lambda: qc.fly("step", 3.0), WRONG, ["controller", "float 3"]),
    # fly: the other arguments
    "fly dt 0": (lambda: qc.fly("step", dt=0), BAD, ["dt", "positive"]),
    "fly dt nan": (lambda: qc.fly("step", dt=math.nan), BAD, ["dt", "nan"]),
    "fly duration -1": (lambda: qc.fly("step", duration=-1.0), BAD, ["duration", "positive"]),
    "fly duration inf": (lambda: qc.fly("step", duration=math.inf), BAD, ["duration", "inf"]),
    "fly max_step str": (lambda: qc.fly("step", max_step="1e-3"), WRONG, ["max_step"]),
    "fly n 0": (lambda: qc.fly("step", n=0), BAD, ["n", ">= 1"]),
    "fly n 2.0": (lambda: qc.fly("step", n=2.0), WRONG, ["n", "float 2"]),
    "fly log_every 0": (lambda: qc.fly("step", log_every=0), BAD, ["log_every", ">= 1"]),
    "fly log_every 1.5": (lambda: qc.fly("step", log_every=1.5), WRONG, ["log_every"]),
    "fly log_every 1500 of 2000": (
        lambda: qc.fly("step", duration=2.0, log_every=1500),
        BAD,
        ["log_every", "2,000 control periods", "1,000, 2,000"],
    ),
    "fly x0 short": (lambda: qc.fly("step", x0=[1.0, 2.0]), WRONG, ["x0", "(16,)"]),
    "fly x0 nan": (lambda: qc.fly("step", x0=np.full(16, np.nan)), BAD, ["x0", "finite"]),
    "fly x0 str": (lambda: qc.fly("step", x0="hover"), WRONG, ["x0"]),
    "fly limits dict": (lambda: qc.fly("step", limits={"max_tilt": 1}), WRONG, ["limits", "Limits"]),
    "fly environment": (
        lambda: qc.fly("step", environment=ConstantWind((1, 0, 0))),
        WRONG,
        ["environment", "Environment"],
    ),
    "fly sensors": (lambda: qc.fly("step", sensors={"position_std": 0.1}), WRONG, ["sensors", "SensorNoise"]),
    "fly missions empty": (lambda: qc.fly(missions=[]), BAD, ["missions", "non-empty"]),
    "fly missions class": (lambda: qc.fly(missions=[Circle(), Circle]), WRONG, ["missions[1]", "Circle()"]),
    "fly missions tuple of str": (lambda: qc.fly(missions="circle"), WRONG, ["missions"]),
    "fly first_vehicle -1": (lambda: qc.fly("step", first_vehicle=-1), BAD, ["first_vehicle"]),
    "fly first_vehicle 1.5": (lambda: qc.fly("step", first_vehicle=1.5), WRONG, ["first_vehicle"]),
    "fly max_track_error 0": (lambda: qc.fly("step", max_track_error=0.0), BAD, ["max_track_error", "positive"]),
    "fly max_steady_error str": (lambda: qc.fly("step", max_steady_error="1"), WRONG, ["max_steady_error"]),
    "fly controller_vehicle": (lambda: qc.fly("step", controller_vehicle="paper"), WRONG, ["controller_vehicle"]),
    "fly unknown mission": (lambda: qc.fly("circel"), BAD, ["unknown mission 'circel'"]),
    # compare
    "compare controllers int": (lambda: qc.compare("step", 3), WRONG, ["controllers", "int 3"]),
    "compare mission class": (lambda: qc.compare(Step), WRONG, ["compare()", "mission", "Step()"]),
    "compare dt str": (lambda: qc.compare("step", ["nlpd"], dt="1e-3"), WRONG, ["compare()", "dt"]),
    "compare vehicle": (lambda: qc.compare("step", ["nlpd"], vehicle=1), WRONG, ["compare()", "vehicle"]),
    "compare progress": (lambda: qc.compare("step", ["nlpd"], progress=1), WRONG, ["progress", "callable"]),
    "compare plain controller": (
        lambda: qc.compare("step", [PlainController()]),
        WRONG,
        ["compare()", "CONTROLLER_SIG"],
    ),
    # montecarlo
    "montecarlo n 0": (lambda: montecarlo("step", n=0), BAD, ["n", ">= 1"]),
    "montecarlo n 2.5": (lambda: montecarlo("step", n=2.5), WRONG, ["n", "float 2.5"]),
    "montecarlo seed 1.5": (lambda: montecarlo("step", n=2, seed=1.5), WRONG, ["seed", "float 1.5"]),
    "montecarlo population": (lambda: montecarlo("step", population="wide", n=2), WRONG, ["population"]),
    "montecarlo chunk_size": (lambda: montecarlo("step", n=2, chunk_size="big"), WRONG, ["chunk_size"]),
    "montecarlo workers 0": (lambda: montecarlo("step", n=2, workers=0), BAD, ["workers", ">= 1"]),
    "montecarlo resume str": (lambda: montecarlo("step", n=2, resume="yes"), WRONG, ["resume", "True or False"]),
    "montecarlo out int": (lambda: montecarlo("step", n=2, out=3), WRONG, ["out", "folder path"]),
    "montecarlo timeout 0": (lambda: montecarlo("step", n=2, connect_timeout=0), BAD, ["connect_timeout"]),
    "montecarlo duration str": (lambda: montecarlo("step", n=2, duration="1"), WRONG, ["duration"]),
    "montecarlo vehicle": (lambda: montecarlo("step", n=2, vehicle=3), WRONG, ["vehicle", "Vehicle"]),
    "montecarlo controller class": (lambda: montecarlo("step", NLPD, n=2), WRONG, ["montecarlo()", "NLPD()"]),
    "montecarlo mission class": (lambda: montecarlo(Circle, n=2), WRONG, ["montecarlo()", "mission"]),
    # tune
    "tune seed 1.5": (lambda: tune("step", targets=RISE, seed=1.5), WRONG, ["seed", "1.5"]),
    "tune budget 0": (lambda: tune("step", targets=RISE, budget=0), BAD, ["budget", ">= 1"]),
    "tune mission class": (lambda: tune(Step, targets=RISE), WRONG, ["tune()", "mission"]),
    "tune dt str": (lambda: tune("step", targets=RISE, dt="1e-3"), WRONG, ["tune()", "dt"]),
    "tune vehicle": (lambda: tune("step", targets=RISE, vehicle=2), WRONG, ["tune()", "vehicle"]),
    "tune tol -1": (lambda: tune("step", targets=RISE, tol=-1.0), BAD, ["tol", ">= 0"]),
    "tune controller class": (lambda: tune("step", NLPD, targets=RISE), WRONG, ["tune()", "NLPD()"]),
    "tune targets text": (lambda: tune("step", targets=["rise_time_s=1"]), WRONG, ["tune()", "targets[0]", "Target"]),
    "tune require text": (lambda: tune("step", targets=RISE, require="rmse_m<1"), WRONG, ["tune()", "require"]),
    "tune bounds text": (lambda: tune("step", targets=RISE, bounds="position.kp=1:9"), WRONG, ["tune()", "bounds"]),
    "tune bounds reversed": (
        lambda: tune("step", targets=RISE, bounds={"position.kp": (9, 1)}),
        BAD,
        ["tune()", "bounds['position.kp']", "low < high"],
    ),
    "tune target negative": (lambda: tune("step", targets={"rmse_m": -1}), BAD, ["tune()", "targets['rmse_m']"]),
    "montecarlo requirements text": (
        lambda: montecarlo("step", n=2, requirements="rmse_m<1"),
        WRONG,
        ["montecarlo()", "requirements", "Requirement"],
    ),
    "montecarlo requirement metric": (
        lambda: montecarlo("step", n=2, requirements={"rmse": ("<", 1)}),
        BAD,
        ["montecarlo()", "requirements key", "did you mean 'rmse_m'?"],
    ),
    # replay
    "replay int": (lambda: qc.replay(3), WRONG, ["commands", "CommandSchedule", "DataFrame", "path"]),
    "replay max_step 0": (lambda: qc.replay(EXAMPLES / "pwm_step.csv", max_step=0.0), BAD, ["max_step"]),
    "replay vehicle": (lambda: qc.replay(EXAMPLES / "pwm_step.csv", vehicle=3), WRONG, ["vehicle", "preset"]),
    "replay vehicle name": (
        lambda: qc.replay(EXAMPLES / "pwm_step.csv", vehicle="crazyfly"),
        BAD,
        ["unknown vehicle preset 'crazyfly'"],
    ),
    "replay full_dynamics": (
        lambda: qc.replay(EXAMPLES / "pwm_step.csv", full_dynamics="no"),
        WRONG,
        ["full_dynamics"],
    ),
    "replay no such file": (lambda: qc.replay("no_such_file.csv"), BAD, ["no_such_file.csv"]),
    # analyze (linearize)
    "linearize dt str": (lambda: linearize("nlpd", dt="1e-3"), WRONG, ["linearize()", "dt"]),
    "linearize vehicle": (lambda: linearize("nlpd", vehicle=3), WRONG, ["vehicle"]),
    "linearize controller class": (lambda: linearize(NLPD), WRONG, ["controller", "NLPD()"]),
    "linearize settle 1.5": (lambda: linearize("nlpd", settle=1.5), WRONG, ["settle"]),
    # parameter objects: the vehicle, missions, disturbances, controllers, limits
    "Vehicle m str": (lambda: qc.Vehicle(m="3.5"), WRONG, ["'m'", "mass", "'3.5'"]),
    "Vehicle m -1": (lambda: qc.Vehicle(m=-1.0), BAD, ["'m'", "> 0"]),
    "Vehicle m list of str": (lambda: qc.Vehicle(m=["a", "b"]), WRONG, ["'m'"]),
    "Circle radius str": (lambda: Circle(radius="2"), WRONG, ["radius", "'2'"]),
    "Circle radius 0": (lambda: Circle(radius=0.0), BAD, ["radius", "> 0"]),
    "Step size 0": (lambda: Step(size=0.0), BAD, ["size", "nonzero"]),
    "SensorNoise str": (lambda: SensorNoise(position_std="x"), WRONG, ["position_std"]),
    "SensorNoise -1": (lambda: SensorNoise(position_std=-1.0), BAD, ["position_std", ">= 0"]),
    "ConstantWind 3": (lambda: ConstantWind(velocity=3.0), WRONG, ["velocity"]),
    "NLPD max_tilt str": (lambda: NLPD(max_tilt="0.5"), WRONG, ["max_tilt"]),
    "NLPD max_tilt 2": (lambda: NLPD(max_tilt=2.0), BAD, ["max_tilt", "pi/2"]),
    "NLPD flag str": (lambda: NLPD(accel_feedforward="no"), WRONG, ["accel_feedforward"]),
    "Limits str": (lambda: Limits(max_tilt="1"), WRONG, ["Limits()", "max_tilt"]),
    "Limits 0": (lambda: Limits(max_position=0.0), BAD, ["max_position", "positive"]),
    "Population str": (lambda: Population(mass_spread="0.1"), WRONG, ["mass_spread"]),
    "Target value str": (lambda: Target("rmse_m", "0.1"), WRONG, ["Target()", "value", "str '0.1'"]),
    "Target metric": (lambda: Target("rmse", 0.1), BAD, ["Target()", "metric", "did you mean 'rmse_m'?"]),
    "Requirement op": (lambda: Requirement("rmse_m", "==", 0.1), BAD, ["Requirement()", "op", "'<='"]),
    "Requirement value nan": (lambda: Requirement("rmse_m", "<", math.nan), BAD, ["Requirement()", "value"]),
    "Bounds reversed": (lambda: Bounds("position.kp", 2, 1), BAD, ["Bounds()", "high", "low = 2"]),
    "Bounds str": (lambda: Bounds("position.kp", "1", 2), WRONG, ["Bounds()", "low", "str '1'"]),
    # issue 33: identify, replay_rotors, read_speed_csv, Vehicle.load; each checked before the file is read
    "identify int": (lambda: qc.identify(123), WRONG, ["identify()", "argument log", "int 123"]),
    "identify progress": (lambda: qc.identify("no_such.ulg", progress=5), WRONG, ["progress", "callable", "int 5"]),
    "identify frame": (lambda: qc.identify("no_such.ulg", frame=1), WRONG, ["identify()", "frame", "int 1"]),
    "identify commands": (lambda: qc.identify("no_such.ulg", commands=None), WRONG, ["commands", "None"]),
    "identify holdout float64": (lambda: qc.identify("x.ulg", holdout=np.float64(2.0)), BAD, ["holdout", "2.0"]),
    "replay_rotors int": (lambda: qc.replay_rotors(3, crazyflie()), WRONG, ["replay_rotors()", "SpeedSchedule"]),
    "replay_rotors no such file": (lambda: qc.replay_rotors("x.csv", crazyflie()), BAD, ["x.csv: no such file"]),
    "replay_rotors wind": (
        lambda: qc.replay_rotors(speeds(), crazyflie(), wind="north"),
        WRONG,
        ["replay_rotors()", "wind", "str 'north'"],
    ),
    "replay_rotors wind short": (lambda: qc.replay_rotors(speeds(), crazyflie(), wind=[1, 2]), BAD, ["wind", "3"]),
    "replay_rotors max_step": (
        lambda: qc.replay_rotors(speeds(), crazyflie(), max_step="small"),
        WRONG,
        ["replay_rotors()", "max_step", "str 'small'"],
    ),
    "replay_rotors ground": (lambda: qc.replay_rotors(speeds(), crazyflie(), ground="no"), WRONG, ["ground"]),
    "replay_rotors progress": (lambda: qc.replay_rotors(speeds(), crazyflie(), progress=1), WRONG, ["progress"]),
    "read_speed_csv n str": (
        lambda: qc.read_speed_csv(SPEEDS, "4"),
        WRONG,
        ["read_speed_csv()", "n_rotors", "str '4'"],
    ),
    "read_speed_csv n 0": (lambda: qc.read_speed_csv(SPEEDS, 0), BAD, ["n_rotors", ">= 1"]),
    "read_speed_csv path": (lambda: qc.read_speed_csv(7, 4), WRONG, ["read_speed_csv()", "path", "int 7"]),
    "read_duty_csv path": (lambda: qc.read_duty_csv(7), WRONG, ["read_duty_csv()", "path", "int 7"]),
    "Vehicle.load int": (lambda: qc.Vehicle.load(123), WRONG, ["Vehicle.load()", "name_or_path", "int 123"]),
    "Vehicle.load list": (lambda: qc.Vehicle.load(["iris"]), WRONG, ["Vehicle.load()", "list ['iris']"]),
    "Vehicle.load unknown": (lambda: qc.Vehicle.load("irys"), BAD, ["unknown vehicle preset 'irys'", "'iris'"]),
    # the gym: gymnasium.make and make_vec hand their keywords to the environment; reset takes a seed
    "make limits": (lambda: gym_make(limits=5), WRONG, ["make()", "limits", "Limits", "int 5"]),
    "make action list": (lambda: gym_make(action=["rotors"]), WRONG, ["make()", "action", "list ['rotors']"]),
    "make scales text": (lambda: gym_make(scales="fast"), WRONG, ["make()", "scales", "str 'fast'"]),
    "make max_step text": (lambda: gym_make(max_step="small"), WRONG, ["make()", "max_step", "str 'small'"]),
    "make dt text": (lambda: gym_make(dt="0.01"), WRONG, ["make()", "dt", "str '0.01'"]),
    "make dt 0": (lambda: gym_make(dt=0.0), BAD, ["make()", "dt", "positive"]),
    "make duration text": (lambda: gym_make(duration="5"), WRONG, ["make()", "duration"]),
    "make_vec dt text": (lambda: gym_make_vec(dt="0.01"), WRONG, ["make()", "dt", "str '0.01'"]),
    "make vehicle int": (lambda: gym_make(vehicle=123), WRONG, ["make()", "vehicle", "int 123"]),
    "make mission int": (lambda: gym_make(mission=5), WRONG, ["make()", "mission", "int 5"]),
    "make population text": (lambda: gym_make(population="wide"), WRONG, ["make()", "population", "str 'wide'"]),
    "make controller int": (lambda: gym_make(controller=5), WRONG, ["make()", "controller", "int 5"]),
    "make max_track_error": (lambda: gym_make(max_track_error=np.float64(-1)), BAD, ["max_track_error", "-1.0"]),
    "make_vec num_envs 1.5": (lambda: gym_make_vec(num_envs=1.5), WRONG, ["make()", "num_envs", "float 1.5"]),
    "make_vec reset seed 1.5": (lambda: gym_make_vec().reset(seed=1.5), WRONG, ["reset()", "seed", "float 1.5"]),
    "make_vec reset seed text": (lambda: gym_make_vec().reset(seed="abc"), WRONG, ["reset()", "seed", "str 'abc'"]),
    "make_vec reset seed -1": (lambda: gym_make_vec().reset(seed=-1), BAD, ["reset()", "seed", ">= 0"]),
    "make reset seed 1.5": (lambda: gym_make().reset(seed=1.5), WRONG, ["reset()", "seed", "float 1.5"]),
}

SPEEDS = "no_such_speeds.csv"  # the arguments are refused before the file is looked for


def crazyflie():
    return qc.Vehicle.load("crazyflie")


def speeds():
    """A two-row schedule of hover speeds for the Crazyflie (what the arguments after it need)."""
    from quadcruise.workflows.replay import SpeedSchedule

    return SpeedSchedule(t=np.array([0.0, 0.1]), speeds=np.full((2, 4), 2000.0), source="two rows")


def gym_make(**kw):
    gymnasium = pytest.importorskip("gymnasium")
    import quadcruise.gym  # noqa: F401 (registers the environments)

    return gymnasium.make("quadcruise/Hover-v0", **kw)


def gym_make_vec(num_envs=2, **kw):
    gymnasium = pytest.importorskip("gymnasium")
    import quadcruise.gym  # noqa: F401

    return gymnasium.make_vec("quadcruise/Hover-v0", num_envs=num_envs, vectorization_mode="vector_entry_point", **kw)


@pytest.mark.parametrize("name", sorted(CASES))
def test_a_bad_argument_is_one_line_naming_it(name):
    call, error, words = CASES[name]
    with pytest.raises(error) as caught:
        call()
    message = str(caught.value)
    assert isinstance(caught.value, InputError), type(caught.value)  # the CLI's exit 2
    assert (error is WRONG) == isinstance(caught.value, TypeError), type(caught.value)
    assert "\n" not in message and len(message) < 400, message
    assert "np." not in message and "was raised from the environment creator" not in message, message
    for word in words:
        assert word in message, (word, message)


def test_the_type_error_is_an_input_error_and_a_type_error():
    assert issubclass(ArgumentTypeError, InputError) and issubclass(ArgumentTypeError, TypeError)
    assert issubclass(InputError, ValueError) and not issubclass(InputError, TypeError)


def test_a_bad_argument_is_refused_before_the_flight_is_sized_or_flown():
    # a flight of hours: the seed is refused first, not the size, and nothing flies (were it
    # flown first, this call would not end)
    with pytest.raises(TypeError, match="seed"):
        qc.fly("circle", duration=3600.0, n=100_000, seed=1.5)


def test_what_must_pass_passes_and_numbers_of_any_numeric_type_fly_the_same():
    ref = qc.fly("step", duration=2.0, dt=1e-3, seed=3, log_every=10, sensors=SensorNoise(position_std=0.01))
    same = qc.fly(
        "step",
        duration=2,
        dt=np.float64(1e-3),
        seed=np.int64(3),
        log_every=np.int32(10),
        full_dynamics=np.bool_(False),
        sensors=SensorNoise(position_std=0.01),
    )
    np.testing.assert_array_equal(ref.states, same.states)
    other = qc.fly("step", duration=2.0, seed=4, log_every=10, sensors=SensorNoise(position_std=0.01))
    assert not np.array_equal(ref.states, other.states)  # the seed is used
    assert ref.meta["seed"] == 3 and isinstance(same.meta["seed"], int)
    assert ref.t[-1] == pytest.approx(2.0)  # the log ends where the flight does
    assert qc.fly("hover", duration=1.0, max_track_error=np.inf, first_vehicle=np.array([0, 5]), n=2).ok.all()
    assert qc.fly(Circle(), missions=None, duration=20.0, log_every=100, limits=Limits(max_tilt=math.inf)).ok.all()


def test_replay_takes_a_path_as_well_as_a_schedule():
    path = EXAMPLES / "pwm_step.csv"
    by_path = qc.replay(str(path))
    by_schedule = qc.replay(qc.read_commands(path))
    np.testing.assert_array_equal(by_path.states, by_schedule.states)
    assert by_path.meta["source"] == str(path)
    assert qc.replay(path).t.size == by_path.t.size  # a pathlib.Path too


def test_a_compiled_controller_of_ones_own_passes_the_check():
    from numba import njit

    from quadcruise.control import as_controller, compiled_for_engine
    from quadcruise.layout import CONTROLLER_SIG

    class Mine(PlainController):
        function = staticmethod(njit(CONTROLLER_SIG, cache=False)(PlainController.function))

    assert compiled_for_engine(Mine().function) and not compiled_for_engine(PlainController().function)
    assert as_controller(Mine()).name == "plain"
    lazily = njit(PlainController.function)  # an @njit without a signature: the check compiles it for the engine
    assert compiled_for_engine(lazily) and tuple(CONTROLLER_SIG.args) in [tuple(s) for s in lazily.signatures]
    assert not compiled_for_engine(njit(lambda t, dt: t + dt))  # one that cannot take the engine's arguments


def test_seed_given_to_fly_is_written_so_that_the_scenario_flies_again(tmp_path):
    res = qc.fly("step", duration=1.0, seed=np.int64(2), sensors=SensorNoise(position_std=0.01))
    res.write(tmp_path / "out")
    text = (tmp_path / "out" / "scenario.toml").read_text()
    assert "seed = 2\n" in text


def test_default_tuning_bounds_stay_within_the_fields_range():
    from quadcruise.tune.space import GainSpace

    for name in ("nlpd", "gonzalez", "se3", "cascade"):
        gain = GainSpace.build(qc_controller(name), "max_tilt").gains[0]
        assert 0 < gain.low < math.radians(45.0) < gain.high < math.pi / 2
        assert gain.high > math.pi / 2 * (1 - 1e-6)  # up to the field's limit


def qc_controller(name):
    from quadcruise.control import controller_from_name

    return controller_from_name(name)


def quadcruise_cli(*args, cwd):
    """The command line of this tree's package, whatever the folder it runs in (its entry
    point in this process: support.entry)."""
    return run_entry(*args, cwd=cwd)


@pytest.mark.parametrize(
    "args, words",
    [
        (["fly", "step", "-m", "size=0"], "step field 'size' (step size, m or rad) must be nonzero, got 0.0"),
        (["fly", "circle", "-m", "period=1e300"], "x 1e+303 control periods is 1e+303 vehicle-steps"),
        (["fly", "circle", "--poles", "0.7,4.3"], "--poles: pole 0.7 is not in the open left half plane"),
        (["fly", "circle", "--poles", "-1,-2,-3"], "--poles needs 2 poles, got 3"),
        (
            ["fly", "{inline}"],
            "[disturbances] unknown key 'sensor_noise.position' (did you mean 'sensor_noise.position_std'?)",
        ),
        (["fly", "{log_every}"], "[simulation] 'log_every' = 1500 does not divide the flight's 2,000 control periods"),
        (["fly", "{batch}"], "the number of vehicles contradicts itself: [vehicle] m gives 2, [simulation] n gives 3"),
        (["fly", "{dt}"], "[simulation] 'dt' = 0.003 s does not divide 'duration' = 2 s into whole control periods"),
    ],
)
def test_scenario_and_number_messages_are_one_short_line_naming_where(tmp_path, args, words):
    files = {
        "inline": "[disturbances]\nsensor_noise = { position = 0.01 }\n",
        "log_every": "[simulation]\nduration = 2.0\ndt = 0.001\nlog_every = 1500\n",
        "batch": "[vehicle]\nm = [3.4, 3.5]\n[simulation]\nn = 3\n",
        "dt": "[simulation]\nduration = 2.0\ndt = 0.003\n",
    }
    for key, text in files.items():
        (tmp_path / f"{key}.toml").write_text(text)
    proc = quadcruise_cli(*(a.format(**{k: f"{k}.toml" for k in files}) for a in args), cwd=tmp_path)
    assert proc.returncode == 2, proc.stdout + proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and words in lines[0], proc.stderr
    assert len(lines[0]) < 300 and "Traceback" not in proc.stderr and "pd_from_poles" not in lines[0]
    if args[1].startswith("{"):
        assert f"{args[1][1:-1]}.toml" in lines[0]  # the file is named
    assert not proc.stdout.strip() and sorted(p.name for p in tmp_path.iterdir()) == sorted(f"{k}.toml" for k in files)


def test_what_must_pass_passes_through_the_issue_33_entries(tmp_path):
    """identify, replay_rotors, read_speed_csv, Vehicle.load and the gym take what they document:
    a path or a schedule, numpy numbers, a seed of any integer type."""
    path = tmp_path / "speeds.csv"
    path.write_text("t,w1,w2,w3,w4\n0,2000,2000,2000,2000\n0.05,2100,2100,2100,2100\n")
    cf = crazyflie()
    by_path = qc.replay_rotors(str(path), cf, wind=np.array([1.0, 0.0, 0.0]), max_step=np.float64(5e-4))
    by_schedule = qc.replay_rotors(qc.read_speed_csv(path, np.int64(4)), cf, wind=(1, 0, 0), max_step=5e-4)
    np.testing.assert_array_equal(by_path.states, by_schedule.states)
    gymnasium = pytest.importorskip("gymnasium")
    import quadcruise.gym  # noqa: F401

    env = gymnasium.make("quadcruise/Hover-v0", dt=np.float64(0.01), max_step=0.005, scales={"max_tilt": 0.4})
    obs_np, _ = env.reset(seed=np.int64(7))
    obs_int, _ = env.reset(seed=7)
    np.testing.assert_array_equal(obs_np, obs_int)
    assert not np.array_equal(env.reset(seed=8)[0], obs_int)  # the seed is used
    vec = gym_make_vec()
    first, _ = vec.reset(seed=np.uint8(3))
    np.testing.assert_array_equal(first, vec.reset(seed=3)[0])


@pytest.mark.parametrize(
    "change, words",
    [
        ('plant = ["rotor"]', "'plant' must be the name of a plant (paper or rotor), got list ['rotor']"),
        ("w_max = 1e200", "vehicle field 'w_max' (1e+200 rad/s) is out of range"),
    ],
)
def test_a_vehicle_file_with_a_wrong_plant_or_an_overflowing_speed_is_one_line(tmp_path, change, words):
    """Vehicle.load, fly --vehicle and identify --vehicle: one line naming the file and the key
    (they raised TypeError: unhashable type, and OverflowError)."""
    from quadcruise.model.vehicle_files import preset_path

    text = preset_path("iris").read_text()
    key = change.split(" = ")[0]
    bad = "\n".join(change if line.startswith(f"{key} = ") else line for line in text.splitlines())
    assert bad != text
    (tmp_path / "v.toml").write_text(bad)
    (tmp_path / "log.ulg").write_bytes(b"")  # the vehicle is refused before the log is read
    with pytest.raises(InputError) as caught:
        qc.Vehicle.load(tmp_path / "v.toml")
    assert words in str(caught.value) and str(tmp_path / "v.toml") in str(caught.value)
    for args in (["fly", "hover", "--duration", "0.1"], ["identify", "log.ulg", "--out", "id"]):
        proc = quadcruise_cli(*args, "--vehicle", "v.toml", cwd=tmp_path)
        assert proc.returncode == 2 and "Traceback" not in proc.stderr, proc.stderr
        assert proc.stderr.count("\n") == 1 and words in proc.stderr
    assert qc.Vehicle.load(preset_path("iris")).w_max == 1100.0  # the file as shipped still loads


def test_a_non_finite_cell_is_named_without_a_numpy_repr(tmp_path):
    (tmp_path / "duties.csv").write_text("t,u1,u2,u3,u4\n0,0.5,0.5,0.5,0.5\n1,inf,0.5,0.5,0.5\n")
    (tmp_path / "speeds.csv").write_text("t,w1,w2,w3,w4\n0,2000,2000,2000,2000\ninf,2000,2000,2000,2000\n")
    with pytest.raises(InputError) as duty:
        qc.read_duty_csv(tmp_path / "duties.csv")
    with pytest.raises(InputError) as speed:
        qc.read_speed_csv(tmp_path / "speeds.csv", 4)
    assert str(duty.value).endswith("line 3, column 'u1': duty is not finite (inf)"), duty.value
    assert str(speed.value).endswith("line 3, column 't': time is not finite (inf)"), speed.value
