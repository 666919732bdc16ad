"""The ``sysid`` mission's reference: consistent derivatives, one axis excited at a time, each
doublet back where it started, the spin undone by the next repeat; registered like the other
kinds; bad fields refused in one line."""

import math

import numpy as np
import pytest
from click.testing import CliRunner

from quadcruise.cli.main import main
from quadcruise.errors import InputError
from quadcruise.layout import REF_AX, REF_AY, REF_AZ, REF_PSI, REF_PSI_DOT, REF_VX, REF_VY, REF_VZ, REF_X, REF_Y, REF_Z
from quadcruise.missions import MISSIONS, Sysid, mission_from_dict, mission_from_name

MISSION = Sysid()
STEP = 1e-4


def integral(values, dt):
    """Cumulative trapezoid from 0: the independent path from a derivative to its signal."""
    return np.concatenate([[0.0], np.cumsum(0.5 * (values[1:] + values[:-1]) * dt)])


def test_velocity_and_position_integrate_the_acceleration_and_yaw_its_rate():
    """The reference is exact kinematics: position is the integral of velocity, velocity of
    acceleration (x, y, z) and yaw of the yaw rate, over the whole mission."""
    t = np.arange(0.0, MISSION.duration, STEP)
    ref = MISSION.reference(t)
    for pos, vel, acc in ((REF_X, REF_VX, REF_AX), (REF_Y, REF_VY, REF_AY), (REF_Z, REF_VZ, REF_AZ)):
        jump = np.max(np.abs(np.diff(ref[:, acc])))  # a sample's half-step at each jump of the acceleration
        assert 0 < np.max(np.abs(integral(ref[:, acc], STEP) - ref[:, vel])) < jump * STEP
        assert np.max(np.abs(ref[0, pos] + integral(ref[:, vel], STEP) - ref[:, pos])) < 1e-6
    assert np.max(np.abs(integral(ref[:, REF_PSI_DOT], STEP) - ref[:, REF_PSI])) < 1e-6


def test_one_axis_at_a_time_and_each_doublet_comes_back():
    """Before the spin: a roll (y), pitch (x), thrust (z) and yaw doublet in turn, each moving
    only its axis, 1-2-1 in acceleration, and ending at the hover point at rest."""
    m = MISSION
    slot = 4 * m.pulse + m.rest
    for j, (moving, acc) in enumerate(((REF_Y, REF_AY), (REF_X, REF_AX), (REF_Z, REF_AZ), (REF_PSI, None))):
        t = m.settle + j * slot + np.arange(0.0, slot, STEP)
        ref = m.reference(t)
        still = [c for c in (REF_X, REF_Y, REF_Z, REF_PSI) if c != moving]
        hover = {REF_X: 0.0, REF_Y: 0.0, REF_Z: m.z, REF_PSI: 0.0}
        for c in still:
            assert np.all(ref[:, c] == hover[c]), (j, c)
        assert np.ptp(ref[:, moving]) > 0.1
        if acc is not None:
            amp = m.climb if moving == REF_Z else m.accel
            seen = ref[[0, 1 * int(m.pulse / STEP) + 1, 3 * int(m.pulse / STEP) + 1, -1], acc]
            assert seen.tolist() == pytest.approx([amp, -amp, amp, 0.0])
        after = m.reference(m.settle + (j + 1) * slot - m.rest / 2)[0]
        assert after[moving] == pytest.approx(hover[moving], abs=1e-12)


def test_the_spin_holds_its_rate_and_the_next_repeat_undoes_it():
    """During the hold the yaw rate is ``spin`` (the roll and pitch doublets fly while
    spinning); the second repeat spins the other way and the mission ends at the first yaw."""
    m = Sysid(yaw=0.3)
    slot = 4 * m.pulse + m.rest
    hold_start = m.settle + 4 * slot + 2 * m.pulse
    ref = m.reference(np.arange(hold_start, hold_start + m.rest + 4 * slot, 0.01))
    assert np.allclose(ref[:, REF_PSI_DOT], m.spin)
    assert np.ptp(ref[:, REF_X]) > 0.1 and np.ptp(ref[:, REF_Y]) > 0.1
    second = m.reference(m.settle + m.period + hold_start - m.settle + 0.5)[0]
    assert second[REF_PSI_DOT] == pytest.approx(-m.spin)
    turn = m.spin * (2 * m.pulse + m.rest + 4 * slot)
    assert m.reference(m.settle + m.period - 0.1)[0, REF_PSI] == pytest.approx(0.3 + turn)
    assert m.reference(m.duration + 1.0)[0, REF_PSI] == pytest.approx(0.3, abs=1e-9)
    assert Sysid(repeats=3).reference(Sysid(repeats=3).duration + 1.0)[0, REF_PSI] == pytest.approx(turn)


def test_duration_and_size():
    m = MISSION
    assert m.duration == pytest.approx(m.settle + m.repeats * (8 * (4 * m.pulse + m.rest) + 4 * m.pulse + 2 * m.rest))
    ref = m.reference(np.arange(0.0, m.duration, 0.01))
    lateral = np.hypot(ref[:, REF_X], ref[:, REF_Y])
    assert lateral.max() == pytest.approx(m.accel * m.pulse**2, rel=1e-3)  # the doublet's widest point, A p^2
    tilt = math.degrees(math.atan(m.accel / 9.81))
    assert 8.0 < tilt < 9.0


def test_registered_like_the_other_kinds():
    assert MISSIONS["sysid"] is Sysid
    m = mission_from_name("sysid", pulse=0.4, repeats=1)
    assert mission_from_dict(m.to_dict()) == m


@pytest.mark.parametrize(
    "fields, message",
    [
        ({"pulse": 0.0}, "sysid field 'pulse' (a doublet's unit step, s) must be > 0, got 0.0"),
        ({"repeats": 0}, "sysid field 'repeats' (times the pattern is flown, -) must be >= 1, got 0"),
        ({"repeats": 1.5}, "sysid field 'repeats' (times the pattern is flown, -) must be a whole number >= 0"),
        ({"spin": -1.0}, "sysid field 'spin' (yaw rate while spinning, rad/s) must be > 0"),
    ],
)
def test_bad_fields_are_one_line(fields, message):
    with pytest.raises(InputError) as caught:
        Sysid(**fields)
    assert str(caught.value).startswith(message)


def test_bad_field_on_the_command_line_is_exit_2_before_flying():
    result = CliRunner().invoke(main, ["fly", "sysid", "-m", "repeats=0"])
    assert result.exit_code == 2
    assert result.stdout == ""
    assert result.stderr.strip().splitlines() == [
        "error: sysid field 'repeats' (times the pattern is flown, -) must be >= 1, got 0"
    ]
