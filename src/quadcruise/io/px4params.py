"""PX4 parameters in and out: a ULog's or a QGroundControl ``.params`` file's, checked against
PX4's ranges (:mod:`quadcruise.io.px4defaults`), and written back as a ``.params`` file.

A QGroundControl parameter file is text, one parameter a line, tab separated::

    # Vehicle-Id Component-Id Name Value Type
    1	1	MC_ROLLRATE_P	0.18	9

with ``#`` comments and MAVLink's ``MAV_PARAM_TYPE`` (9 a 32-bit float, 6 a 32-bit integer;
1-8 the other integer widths). A ULog holds the parameters at the start of the log
(``initial_parameters``) and the changes made in flight (``changed_parameters``); the values
read are those at the log's end (each change applied in order).

Only the parameters the PX4 loops use (:data:`~quadcruise.io.px4defaults.PX4_PARAMETERS`) are
checked; the others are kept by name in :attr:`Px4Parameters.unused`, so that a caller can
say once which were not used.
"""

from __future__ import annotations

import dataclasses
import math
import os
import struct
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from quadcruise.errors import InputError
from quadcruise.io.files import atomic_path
from quadcruise.io.px4defaults import FLOAT, INT32, PX4_PARAMETERS, RELEASE

__all__ = [
    "Px4Parameters",
    "read_params",
    "parse_params_text",
    "write_params",
    "params_text",
    "changed",
    "px4_constrained",
]

INTEGER_TYPES = frozenset(range(1, 9))
"""MAV_PARAM_TYPE of the integers (UINT8 .. INT64); 9 is REAL32, 10 REAL64."""


@dataclass(frozen=True)
class Px4Parameters(Mapping):
    """PX4 parameters by name, as read from ``source``; a mapping name -> value.

    ``values`` holds every parameter the loops use: the file's where it has them, PX4
    v1.15's default elsewhere (:attr:`from_file` says which came from the file).

    Parameters
    ----------
    values : dict of str to float
        Each used parameter's value, in PX4's units.
    source : str
        Where they were read (a path, or ``"defaults"``).
    from_file : tuple of str
        The used parameters the source set.
    unused : tuple of str
        The source's parameters the loops do not use, sorted.
    notes : tuple of str
        What a reader should be told of the source once (:func:`read_params`): a log of another
        PX4 release lacking parameters the loops use (flown at v1.15's defaults), older names
        of the loops' parameters (not converted).

    Examples
    --------
    >>> p = Px4Parameters.defaults()
    >>> p["MC_ROLLRATE_P"], p.source
    (0.15, 'defaults')
    """

    values: dict
    source: str = "defaults"
    from_file: tuple = ()
    unused: tuple = field(default=())
    notes: tuple = field(default=(), compare=False)

    @classmethod
    def defaults(cls) -> Px4Parameters:
        """PX4 v1.15's defaults of every parameter the loops use."""
        return cls({k: float(v.default) for k, v in PX4_PARAMETERS.items()})

    def __getitem__(self, name: str) -> float:
        return self.values[name]

    def __iter__(self):
        return iter(self.values)

    def __len__(self) -> int:
        return len(self.values)

    def unit_of(self, name: str) -> str:
        """PX4's unit of a parameter ("-" where PX4 gives none).

        Parameters
        ----------
        name : str
            A parameter the loops use.

        Returns
        -------
        str
        """
        return PX4_PARAMETERS[name].unit or "-"

    def bounds_of(self, name: str) -> tuple[float, float, str]:
        """PX4's range of a parameter, as a search's bounds are cut to it.

        Parameters
        ----------
        name : str
            A parameter the loops use.

        Returns
        -------
        tuple
            ``(low, high, "[]")``, infinite where PX4 declares no bound.
        """
        spec = PX4_PARAMETERS[name]
        low = -math.inf if spec.minimum is None else float(spec.minimum)
        high = math.inf if spec.maximum is None else float(spec.maximum)
        return low, high, "[]"

    def with_values(self, **values: float) -> Px4Parameters:
        """A copy with ``values`` set, each checked against PX4's range.

        Parameters
        ----------
        **values : float
            Parameters by PX4's name, in PX4's units.

        Returns
        -------
        Px4Parameters
            The copy (``from_file`` counts the names set here as given).

        Raises
        ------
        InputError
            For a name the loops do not use or a value outside PX4's range.
        """
        merged = dict(self.values)
        for name, value in values.items():
            merged[name] = _checked(name, value, "argument")
        return Px4Parameters(
            merged, self.source, tuple(sorted(set(self.from_file) | set(values))), self.unused, self.notes
        )


def _num(value: float) -> str:
    """A value as a message shows it: enough digits that one just outside a bound does not
    read as the bound (``12.00001``, not ``12``)."""
    return f"{value:.12g}"


def _checked(name: str, value, where: str) -> float:
    """``value`` as a float if ``name`` is used and the value lies within PX4's range."""
    spec = PX4_PARAMETERS.get(name)
    if spec is None:
        raise InputError(f"{where}: {name} is not a parameter of the PX4 loops (see docs/px4.md)")
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{where}: {name} = {value!r} is not a number") from None
    if not math.isfinite(number):
        raise InputError(f"{where}: {name} = {value} is not a finite number")
    if spec.kind == INT32 and number != round(number):
        raise InputError(f"{where}: {name} = {_num(number)} is not an integer (PX4 declares it INT32)")
    low = -math.inf if spec.minimum is None else spec.minimum
    high = math.inf if spec.maximum is None else spec.maximum
    # PX4 stores floats as float32: a bound is met when the float32 values meet it
    n32, lo32, hi32 = (float(np.float32(v)) for v in (number, low, high))
    if not lo32 <= n32 <= hi32:
        lo = "-inf" if spec.minimum is None else f"{spec.minimum:g}"
        hi = "inf" if spec.maximum is None else f"{spec.maximum:g}"
        unit = f" {spec.unit}" if spec.unit else ""
        raise InputError(f"{where}: {name} = {_num(number)}{unit} is outside PX4 {RELEASE}'s range [{lo}, {hi}]")
    return number


RENAMED = {
    "MPC_XY_VEL_P": "MPC_XY_VEL_P_ACC",
    "MPC_XY_VEL_I": "MPC_XY_VEL_I_ACC",
    "MPC_XY_VEL_D": "MPC_XY_VEL_D_ACC",
    "MPC_Z_VEL_P": "MPC_Z_VEL_P_ACC",
    "MPC_Z_VEL_I": "MPC_Z_VEL_I_ACC",
    "MPC_Z_VEL_D": "MPC_Z_VEL_D_ACC",
}
"""Older PX4 releases' names of parameters the loops use (the velocity gains were in thrust, not
acceleration, before PX4 v1.11): read as unused, never converted, and said."""


def _collect(raw: dict, where_of, source: str, release: str | None = None) -> Px4Parameters:
    """The used parameters of ``raw`` checked, the others listed; ``release`` (a log's PX4
    version, a log holding every parameter of its release) makes a note of the used ones it lacks."""
    values = {k: float(v.default) for k, v in PX4_PARAMETERS.items()}
    for name, value in raw.items():
        if name in PX4_PARAMETERS:
            values[name] = _checked(name, value, where_of(name))
    used = tuple(sorted(n for n in raw if n in PX4_PARAMETERS))
    unused = tuple(sorted(n for n in raw if n not in PX4_PARAMETERS))
    notes = []
    old = sorted(n for n in raw if n in RENAMED and RENAMED[n] not in raw)
    if old:
        notes.append(
            f"{source} names {', '.join(old)}, an older PX4 release's gains in other units (now "
            f"{', '.join(RENAMED[n] for n in old)}): not converted, PX4 {RELEASE}'s defaults flown for them"
        )
    if release is not None:
        lacking = sorted(n for n in PX4_PARAMETERS if n not in raw and not n.startswith("CA_"))
        if lacking:
            notes.append(
                f"{source} is a log of {release}, not PX4 {RELEASE}: it has no {', '.join(lacking)}; "
                f"PX4 {RELEASE}'s defaults are flown for them"
            )
    return Px4Parameters(values, source, used, unused, tuple(notes))


def parse_params_text(text: str, source: str = "<text>") -> Px4Parameters:
    """Parameters from a QGroundControl ``.params`` file's text.

    Parameters
    ----------
    text : str
        The file's text.
    source : str
        Its name, for messages.

    Returns
    -------
    Px4Parameters

    Raises
    ------
    InputError
        One line naming the file, the line and the parameter: a line that is not five fields,
        a type that is not MAV_PARAM_TYPE (or not the one PX4 declares), a value that is not a
        number (or not an integer for an integer type), a parameter twice, parameters of two
        vehicles, a used parameter outside PX4's range. Parameters of a component other than
        the autopilot (Component-Id 1) are listed as unused, as ``NAME@componentID``.

    Examples
    --------
    >>> p = parse_params_text("# a comment\\n1\\t1\\tMC_ROLL_P\\t7.5\\t9\\n1\\t1\\tSYS_AUTOSTART\\t4001\\t6\\n")
    >>> p["MC_ROLL_P"], p.unused
    (7.5, ('SYS_AUTOSTART',))
    >>> parse_params_text("1\\t1\\tMC_ROLL_P\\t30\\t9\\n", "my.params")
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: my.params, line 1: MC_ROLL_P = 30 1/s is outside PX4 v1.15's range [0, 12]
    """
    raw: dict[str, float] = {}
    lines: dict[str, int] = {}
    vehicles: dict[int, int] = {}  # Vehicle-Id -> its first line
    text = text.removeprefix("\ufeff")  # a byte-order mark (a file saved by Windows' Notepad)
    for number, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            continue
        fields = stripped.split("\t") if "\t" in stripped else stripped.split()
        fields = [f.strip() for f in fields]
        where = f"{source}, line {number}"
        if len(fields) != 5:
            raise InputError(
                f"{where}: not a QGroundControl parameter line (Vehicle-Id Component-Id Name Value Type, "
                f"tab separated): {stripped[:60]!r}"
            )
        vehicle, component, name, value, kind = fields
        if not (vehicle.isdigit() and component.isdigit()):
            raise InputError(
                f"{where}: {name}: Vehicle-Id {vehicle!r} and Component-Id {component!r} must be whole numbers "
                "(a QGroundControl parameter line: Vehicle-Id Component-Id Name Value Type)"
            )
        try:
            kind_number = int(kind)
        except ValueError:
            kind_number = -1
        if kind_number not in INTEGER_TYPES and kind_number not in (9, 10):
            raise InputError(f"{where}: {name}: type {kind!r} is not a MAV_PARAM_TYPE (9 float, 6 int32, 1-10)")
        try:
            parsed = float(value)
        except ValueError:
            raise InputError(f"{where}: {name} = {value!r} is not a number") from None
        if not math.isfinite(parsed):
            raise InputError(f"{where}: {name} = {value!r} is not a finite number")
        if kind_number in INTEGER_TYPES and parsed != round(parsed):
            raise InputError(f"{where}: {name} = {value!r} is not an integer (type {kind_number})")
        vehicles.setdefault(int(vehicle), number)
        if len(vehicles) > 1:
            first = ", ".join(f"{v} (line {n})" for v, n in vehicles.items())
            raise InputError(f"{where}: {name}: the file holds the parameters of vehicles {first}; give one vehicle's")
        if int(component) != 1:  # another component's (a gimbal, a camera): not the autopilot's loops
            name = f"{name}@component{int(component)}"
        spec = PX4_PARAMETERS.get(name)
        if spec is not None and (spec.kind == INT32) != (kind_number in INTEGER_TYPES):
            declared = "INT32 (type 6)" if spec.kind == INT32 else "FLOAT (type 9)"
            raise InputError(
                f"{where}: {name} has type {kind_number} but PX4 declares it {declared} "
                "(QGroundControl refuses such a line as a type mismatch)"
            )
        if name in raw:
            raise InputError(f"{where}: {name} is set twice (first on line {lines[name]})")
        raw[name], lines[name] = parsed, number
    if not raw:
        raise InputError(f"{source}: no parameters: not a QGroundControl .params file")
    return _collect(raw, lambda n: f"{source}, line {lines[n]}", source)


def _exact_values(text, raw: dict) -> dict:
    """A quadcruise log's exact float64 values (info ``quadcruise_px4_params``, ``NAME=repr;...``)
    of the float32 parameters they round to: the section's value wins where it is not theirs."""
    out = {}
    for item in text.split(";") if isinstance(text, str) and text else ():
        name, _, value = item.partition("=")
        try:
            number = float(value)
        except ValueError:
            continue
        if name in raw and np.float32(number) == np.float32(raw[name]):
            out[name] = number
    return out


def _read_ulog_params(path: Path) -> Px4Parameters:
    from pyulog import ULog
    from pyulog.core import ULogException

    from quadcruise.io.logchecks import check_ulog_framing

    check_ulog_framing(path)
    try:
        log = ULog(str(path), message_name_filter_list=[])
    except (ULogException, struct.error, ValueError, IndexError) as exc:
        raise InputError(f"{path}: not a readable PX4 log ({exc})") from None
    raw = dict(log.initial_parameters)
    moved = set()  # used parameters whose value changed in the log (pyulog without data: no times)
    for _, name, value in log.changed_parameters:
        if name in PX4_PARAMETERS and name in raw and value != raw[name]:
            moved.add(name)
        raw[name] = value
    if not raw:
        raise InputError(f"{path}: the log holds no parameters")
    raw.update(_exact_values(log.msg_info_dict.get("quadcruise_px4_params"), raw))
    version = log.msg_info_dict.get("ver_sw_release")  # 0xMMmmppTT, TT: 0 dev, 64 alpha, 128 beta, 192 rc, 255
    if isinstance(version, int) and version:
        kind = {0: " (dev)", 64: " (alpha)", 128: " (beta)", 192: " (rc)", 255: ""}.get(version & 0xFF, "")
        release = f"PX4 v{version >> 24}.{(version >> 16) & 0xFF}.{(version >> 8) & 0xFF}{kind}"
    else:
        release = "a PX4 release it does not state"
    read = _collect(raw, lambda n: f"{path}", str(path), release)
    if moved:
        note = (
            f"{path} changes {', '.join(sorted(moved))} during the log: the values at its end are used "
            "for the whole log"
        )
        read = dataclasses.replace(read, notes=(*read.notes, note))
    return read


def read_params(path: str | os.PathLike) -> Px4Parameters:
    """PX4 parameters from a ULog (``.ulg``) or a QGroundControl file (``.params``, ``.txt``).

    Parameters
    ----------
    path : str or os.PathLike
        The file.

    Returns
    -------
    Px4Parameters
        Every parameter the loops use (the file's, else PX4 v1.15's default); the file's
        others in ``unused``.

    Raises
    ------
    InputError
        One line naming the file (and line and parameter): a missing file, another format, an
        unreadable log, a bad line, a value out of PX4's range.

    Examples
    --------
    >>> read_params("gains.yaml")
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: gains.yaml: PX4 parameters come from a PX4 log (.ulg) or a QGroundControl ...
    """
    path = Path(path)
    kind = path.suffix.lower()
    if kind not in (".ulg", ".params", ".txt"):
        raise InputError(
            f"{path}: PX4 parameters come from a PX4 log (.ulg) or a QGroundControl file (.params), got {path.suffix!r}"
        )
    if not path.is_file():
        raise InputError(f"{path}: no such file")
    if kind == ".ulg":
        return _read_ulog_params(path)
    try:
        text = path.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError:
        raise InputError(f"{path}: not a text file: not a QGroundControl .params file") from None
    return parse_params_text(text, str(path))


def px4_constrained(values: Mapping[str, float]) -> tuple[dict[str, float], tuple[str, ...]]:
    """The parameters as PX4 flies them after ``MulticopterPositionControl::parameters_update``
    constrains them, and PX4's word for each change.

    PX4 v1.15 sets (and commits) ``MPC_TILTMAX_LND`` to ``MPC_TILTMAX_AIR`` where it is larger
    ("Land tilt has been constrained by max tilt") and ``MPC_THR_HOVER`` into
    ``[MPC_THR_MIN, MPC_THR_MAX]`` (``math::constrain``: "Hover thrust has been constrained by
    min/max"), each within its own range.

    Parameters
    ----------
    values : Mapping of str to float
        Every parameter the loops use (a :class:`Px4Parameters`).

    Returns
    -------
    values : dict
        The parameters, the constrained ones changed.
    notes : tuple of str
        One line per change, naming the parameter, its value and what PX4 flies.

    Examples
    --------
    >>> v, notes = px4_constrained(Px4Parameters.defaults().with_values(MPC_THR_HOVER=0.2, MPC_THR_MIN=0.4))
    >>> v["MPC_THR_HOVER"], notes[0][:60]
    (0.4, 'MPC_THR_HOVER = 0.2 is outside [MPC_THR_MIN, MPC_THR_MAX] = ')
    """
    out = dict(values)
    notes = []
    air, lnd = out["MPC_TILTMAX_AIR"], out["MPC_TILTMAX_LND"]
    if lnd > air:
        out["MPC_TILTMAX_LND"] = air
        notes.append(
            f"MPC_TILTMAX_LND = {_num(lnd)} deg is above MPC_TILTMAX_AIR = {_num(air)} deg: PX4 constrains it "
            f"to {_num(air)} deg (Land tilt has been constrained by max tilt)"
        )
    hover, low, high = out["MPC_THR_HOVER"], out["MPC_THR_MIN"], out["MPC_THR_MAX"]
    if hover > high or hover < low:
        flown = low if hover < low else high  # math::constrain(val, min, max)
        out["MPC_THR_HOVER"] = flown
        notes.append(
            f"MPC_THR_HOVER = {_num(hover)} is outside [MPC_THR_MIN, MPC_THR_MAX] = [{_num(low)}, {_num(high)}]: "
            f"PX4 constrains it to {_num(flown)} (Hover thrust has been constrained by min/max)"
        )
    return out, tuple(notes)


def changed(values: Mapping[str, float]) -> dict[str, float]:
    """The used parameters of ``values`` whose float32 value differs from PX4 v1.15's default.

    Examples
    --------
    >>> changed({"MC_ROLL_P": 6.5, "MC_PITCH_P": 7.0})
    {'MC_PITCH_P': 7.0}
    """
    out = {}
    for name, value in values.items():
        spec = PX4_PARAMETERS.get(name)
        if spec is not None and np.float32(value) != np.float32(spec.default):
            out[name] = float(value)
    return out


def params_text(values: Mapping[str, float], vehicle_id: int = 1, component_id: int = 1, note: str = "") -> str:
    """A QGroundControl ``.params`` file's text: the parameters that differ from the defaults.

    Floats are written as Python's shortest repr (read back to the same float64), integers
    as integers; the header names the PX4 release whose defaults were left out.

    Parameters
    ----------
    values : Mapping of str to float
        Parameters by name (each checked against PX4's range).
    vehicle_id, component_id : int
        MAVLink ids (QGroundControl's first two columns).
    note : str
        More comment lines (e.g. the command that made it), each written as a comment.

    Returns
    -------
    str
        The file's text, ending in a newline.

    Examples
    --------
    >>> print(params_text({"MC_ROLL_P": 7.25, "MC_PITCH_P": 6.5, "MPC_USE_HTE": 0}).splitlines()[-2:])
    ['1\\t1\\tMC_ROLL_P\\t7.25\\t9', '1\\t1\\tMPC_USE_HTE\\t0\\t6']
    """
    diff = changed({k: _checked(k, v, "parameters") for k, v in values.items()})
    lines = [
        "# Onboard parameters for Vehicle 1, written by quadcruise",
        f"# PX4 {RELEASE}: only the parameters that differ from its defaults",
    ]
    lines += [f"# {line}" for line in note.splitlines()]  # each line a comment
    lines += ["#", "# Vehicle-Id\tComponent-Id\tName\tValue\tType"]
    for name in sorted(diff):
        spec = PX4_PARAMETERS[name]
        value = diff[name]
        text = str(int(round(value))) if spec.kind == INT32 else repr(float(value))
        lines.append(f"{vehicle_id}\t{component_id}\t{name}\t{text}\t{INT32 if spec.kind == INT32 else FLOAT}")
    return "\n".join(lines) + "\n"


def write_params(path: str | os.PathLike, values: Mapping[str, float], note: str = "") -> Path:
    """Write ``values`` as a QGroundControl ``.params`` file (:func:`params_text`), atomically.

    Raises
    ------
    InputError
        For a value outside PX4's range (nothing is written).
    WriteError
        If the file could not be written.
    """
    text = params_text(values, note=note)
    path = Path(path)
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return path
