"""The rotor-plant vehicle and the presets: what flies is accepted, what cannot is refused with
one line naming the field or the file and key."""

from __future__ import annotations

import math

import numpy as np
import pytest

from quadcruise import InputError, Vehicle
from quadcruise.model.rotor_plant import ROTOR_P_KF, ROTOR_P_N_ROTORS, ROTOR_P_ROTORS, ROTOR_P_TAU_DOWN
from quadcruise.model.rotor_vehicle import RotorVehicle
from quadcruise.model.vehicle_files import PRESETS, preset_source

ROTOR_PRESETS = ("crazyflie", "hummingbird", "iris")


def test_the_paper_preset_is_table_one_bit_for_bit():
    v = Vehicle.preset("paper")
    assert type(v) is Vehicle
    assert np.array_equal(v.rows(), Vehicle.paper().rows())


@pytest.mark.parametrize("name", ROTOR_PRESETS)
def test_each_rotor_preset_hovers_within_its_speed_range_and_cites_its_source(name):
    v = Vehicle.preset(name)
    assert isinstance(v, RotorVehicle) and v == RotorVehicle.preset(name)
    assert v.source and preset_source(name) == v.source
    assert v.w_min < v.hover_speed < v.w_max
    # the hover speed carries the weight: n kf w^2 = m g
    assert v.n_rotors * v.kf * v.hover_speed**2 == pytest.approx(v.m * v.g, rel=1e-12)
    # each preset is an "x" quad whose drag moments cancel in hover
    assert sum(r[3] for r in v.rotors) == 0


def test_rotorpy_numbers_and_rotor_order():
    """The crazyflie and hummingbird files carry RotorPy 3.0's numbers (its parameter files)."""
    rotorpy_params = pytest.importorskip("rotorpy.vehicles.crazyflie_params")
    import rotorpy.vehicles.hummingbird_params as hb

    for name, params in (("crazyflie", rotorpy_params.quad_params), ("hummingbird", hb.quad_params)):
        v = RotorVehicle.preset(name)
        assert (v.m, v.Jxx, v.Jyy, v.Jzz) == (params["mass"], params["Ixx"], params["Iyy"], params["Izz"])
        assert (v.kf, v.km, v.k_d, v.k_z, v.k_h, v.k_flap) == (
            params["k_eta"],
            params["k_m"],
            params["k_d"],
            params["k_z"],
            params["k_h"],
            params["k_flap"],
        )
        assert (v.c_Dx, v.c_Dy, v.c_Dz) == (params["c_Dx"], params["c_Dy"], params["c_Dz"])
        assert v.tau_up == v.tau_down == params["tau_m"]
        assert (v.w_min, v.w_max) == (params["rotor_speed_min"], params["rotor_speed_max"])
        positions = np.array([params["rotor_pos"][f"r{i + 1}"] for i in range(4)])
        assert np.array_equal(np.array(v.rotors)[:, :3], positions)
        assert np.array_equal(np.array(v.rotors)[:, 3], params["rotor_directions"])


def test_row_layout():
    v = RotorVehicle.preset("iris")
    row = v.row()
    assert row[ROTOR_P_KF] == v.kf and row[ROTOR_P_TAU_DOWN] == v.tau_down and row[ROTOR_P_N_ROTORS] == 4
    assert np.array_equal(row[ROTOR_P_ROTORS:].reshape(4, 4), np.array(v.rotors))


CF = RotorVehicle.preset("crazyflie")


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"w_max": 1000.0}, "vehicle cannot lift itself: 4 rotors x kf w_max^2 = 0.092 N, its weight m g = 0.2943 N"),
        ({"m": 1.0}, "cannot lift itself"),
        ({"tau_up": -0.01}, "vehicle field 'tau_up' (motor time constant speeding up, s) must be > 0, got -0.01"),
        ({"tau_down": 0.0}, "'tau_down'"),
        ({"w_min": 3000.0}, "'w_max' (2500 rad/s) must be above 'w_min' (3000 rad/s)"),
        (
            {"rotors": [[0.05, 0.05, 0, 1], [0.05, -0.05, 0, -1], [0.02, 0.0, 0, 1], [0.03, 0.01, 0, -1]]},
            "the rotors do not surround the centre of mass",
        ),
        (
            {"rotors": [[0.05, 0.0, 0, 1], [-0.05, 0.0, 0, -1], [0.1, 0.0, 0, 1]]},  # all on one line
            "the rotors do not surround the centre of mass",
        ),
        ({"rotors": [[0.05, 0.05, 0, 2], [0.05, -0.05, 0, -1], [-0.05, 0.0, 0, 1]]}, "direction 2 for rotor 1"),
        ({"rotors": [[0.05, 0.05, 0, 1], [0.05, -0.05, 0, -1]]}, "at least 3 rows"),
        ({"k_d": -1e-7}, "'k_d' (rotor drag coefficient"),
        ({"m": math.nan}, "'m' (mass, kg)"),
    ],
)
def test_a_vehicle_that_cannot_fly_is_refused_in_one_line(changes, message):
    with pytest.raises(InputError) as info:
        CF.replace(**changes)
    assert message in str(info.value) and "\n" not in str(info.value)


def test_what_can_fly_is_accepted():
    # a hexarotor, rotors around the centre at 60 degrees, directions alternating
    hexa = [[0.2 * math.cos(k * math.pi / 3), 0.2 * math.sin(k * math.pi / 3), 0.0, (-1) ** k] for k in range(6)]
    v = CF.replace(rotors=hexa, m=0.04)
    assert v.n_rotors == 6 and v.row().shape == (ROTOR_P_ROTORS + 24,)
    # just able to lift itself; and a "+" quad with a rotor on each axis
    just = CF.replace(w_max=math.sqrt(CF.m * CF.g / (4 * CF.kf)) * 1.001)
    assert just.w_max > just.hover_speed
    plus = CF.replace(rotors=[[0.05, 0, 0, 1], [0, 0.05, 0, -1], [-0.05, 0, 0, 1], [0, -0.05, 0, -1]])
    assert plus.n_rotors == 4
    assert CF.without_aero().k_d == 0.0 and CF.without_aero().kf == CF.kf


def test_unknown_presets_and_bad_files(tmp_path):
    with pytest.raises(InputError, match="unknown vehicle preset 'crazyfly' \\(did you mean 'crazyflie'\\?\\)"):
        Vehicle.preset("crazyfly")
    with pytest.raises(InputError, match="must be for the rotor plant"):
        RotorVehicle.preset("paper")
    f = tmp_path / "mine.toml"
    f.write_text('[vehicle]\npreset = "iris"\nJxx = 0.03\nk_d = 0\n')
    v = Vehicle.load(f)
    assert (v.Jxx, v.k_d, v.m) == (0.03, 0.0, RotorVehicle.preset("iris").m)
    assert Vehicle.load(str(f)) == v
    for text, message in [
        (
            '[vehicle]\npreset = "iris"\ntau_upp = 1.0\n',
            "mine.toml: [vehicle] has no key 'tau_upp' for the rotor plant (did you mean 'tau_up'?)",
        ),
        ('[vehicle]\npreset = "iris"\ntau_down = -1\n', "mine.toml: [vehicle] vehicle field 'tau_down'"),
        ('[vehicle]\npreset = "nope"\n', "unknown vehicle preset 'nope'"),
        ('[vehicle]\npreset = "paper"\nrotors = []\n', "has no key 'rotors' for the paper plant"),
        ('[vehicle]\npreset = "iris"\nplant = "paper"\n', "does not match preset 'iris'"),
        ("[vehicle]\nm = 1.0\nJxx = [\n", "mine.toml: not valid TOML"),
        ("[vehicel]\nm = 1.0\n", "mine.toml: unknown table or key 'vehicel'"),
        ('[vehicle]\nplant = "rotor"\nm = 1.0\n', "mine.toml: [vehicle] lacks 'Jxx', 'Jyy', 'Jzz', 'kf', "),
    ]:
        f.write_text(text)
        with pytest.raises(InputError) as info:
            Vehicle.load(f)
        assert message in str(info.value) and "\n" not in str(info.value), str(info.value)
    with pytest.raises(InputError, match="no such file"):
        Vehicle.load(tmp_path / "absent.toml")


def test_every_preset_file_is_a_complete_vehicle_on_its_own(tmp_path):
    """A user copies a preset file and edits it: it loads as it is, to the same vehicle."""
    for name, path in PRESETS.items():
        copy = tmp_path / f"{name}.toml"
        copy.write_text(path.read_text())
        assert Vehicle.load(copy) == Vehicle.preset(name)
