"""A damaged flight log refused in one line naming the file and what is wrong, before any work.

What a PX4 log must be before :mod:`quadcruise.io.flightlog` reads numbers from it:

- **framing**: ULog's header, then messages whose lengths add up to the file's size, each of a
  type the format defines, each data message of a topic the log added and as long as that
  topic's other data messages (a length field damaged to 65535 breaks this; pyulog reads on past
  it, printing "most likely corrupt", and hands back whatever it found);
- **fields**: every field the reader takes (``vehicle_local_position.vx``, ...) in the topic's format;
- **parameters**: ``CA_ROTOR_COUNT`` a whole number of rotors in [1, 12] (PX4's), ``THR_MDL_FAC`` in
  [0, 1], rotor positions ``CA_ROTORi_PX/PY`` that span the plane (roll and pitch moments);
- **clock**: each topic's timestamps never going back (a clock jump would fold two stretches of
  the flight onto one another);
- **values**: finite numbers, unit quaternions, wherever the airborne stretch uses them.

Examples
--------
>>> check_rotor_count("a.ulg", {"CA_ROTOR_COUNT": -1})
Traceback (most recent call last):
    ...
quadcruise.errors.InputError: a.ulg: parameter CA_ROTOR_COUNT = -1: a multicopter has 1 to 12 rotors (PX4's range)
"""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np

from quadcruise.errors import InputError

ULOG_MAGIC = b"ULog\x01\x12\x35"
"""The first seven bytes of every ULog file."""
MESSAGE_TYPES = frozenset(b"BFIMPQARDLCSO")
"""The message types of PX4's ULog format (``dev/log/ulog_file_format``)."""
MAX_ROTORS = 12
"""``CA_ROTOR_COUNT``'s largest value in PX4."""


def check_ulog_framing(path: Path) -> None:
    """Refuse a file that is not a ULog, is truncated, or whose messages do not frame it.

    Raises
    ------
    InputError
        Not ULog's header; a message running past the end (truncated); stray bytes at the end;
        a message of a type ULog does not define; a data message of a topic never added, or of
        another length than its topic's first (a damaged length field).
    """
    data = path.read_bytes()
    if len(data) < 16 or data[:7] != ULOG_MAGIC:
        raise InputError(f"{path}: not a PX4 log (ULog): its first bytes are not ULog's header")
    pos, size = 16, len(data)
    lengths: dict[int, int] = {}
    added: set[int] = set()
    previous = None
    while pos + 3 <= size:
        length, kind = struct.unpack_from("<HB", data, pos)
        if kind not in MESSAGE_TYPES:
            after = f" (after the message at byte {previous[0]}, {previous[1]} bytes long)" if previous else ""
            raise InputError(
                f"{path}: corrupt PX4 log: byte {pos} starts a message of type {kind:#04x}, which ULog does not "
                f"define{after}"
            )
        if pos + 3 + length > size:
            raise InputError(
                f"{path}: truncated PX4 log: the message at byte {pos} needs {length} bytes, "
                f"the file ends after {size - pos - 3}"
            )
        if kind == ord("A") and length >= 3:
            added.add(struct.unpack_from("<H", data, pos + 4)[0])
        elif kind == ord("D") and length >= 2:
            (msg_id,) = struct.unpack_from("<H", data, pos + 3)
            if msg_id not in added:
                raise InputError(f"{path}: corrupt PX4 log: the data message at byte {pos} is of a topic never added")
            first = lengths.setdefault(msg_id, length)
            if length != first:
                raise InputError(
                    f"{path}: corrupt PX4 log: the data message at byte {pos} says it is {length} bytes long, "
                    f"its topic's others {first} (a damaged length field)"
                )
        previous = (pos, length)
        pos += 3 + length
    if pos != size:
        raise InputError(f"{path}: truncated PX4 log: {size - pos} stray byte(s) at its end")


def check_fields(path: Path, topics: dict, needs: dict[str, list[str]]) -> None:
    """Refuse a topic whose format lacks a field the reader takes (``needs``: topic -> fields;
    a topic not in ``topics`` is left to the missing-topic check)."""
    for name, fields in needs.items():
        if name not in topics:
            continue
        missing = [f for f in fields if f not in topics[name]]
        if missing:
            raise InputError(
                f"{path}: topic {name} has no field {', '.join(missing)} (its format is not PX4's: a damaged "
                "or foreign log)"
            )


def check_rotor_count(path, params: dict) -> int:
    """``CA_ROTOR_COUNT`` (4 where the log has none, or 0), refused outside [1, 12] or not whole."""
    value = params.get("CA_ROTOR_COUNT", 0)
    if value is None or value == 0:
        return 4
    if float(value) != int(value) or not 1 <= int(value) <= MAX_ROTORS:
        raise InputError(
            f"{path}: parameter CA_ROTOR_COUNT = {value:g}: a multicopter has 1 to {MAX_ROTORS} rotors (PX4's range)"
        )
    return int(value)


def check_geometry(path, rotors: np.ndarray | None) -> None:
    """Refuse rotor positions (FLU x, y [m]) that do not span the plane: all at the centre, or on
    one line, no roll or no pitch moment to identify."""
    if rotors is None:
        return
    xy = np.asarray(rotors, dtype=np.float64)[:, :2]
    n = len(xy)
    if not np.all(np.isfinite(xy)):
        raise InputError(f"{path}: parameters CA_ROTOR0..{n - 1}_PX/PY: not finite numbers")
    if np.max(np.abs(xy)) == 0.0:
        raise InputError(
            f"{path}: parameters CA_ROTOR0..{n - 1}_PX/PY put every rotor at the centre (0, 0): no roll or pitch "
            "moment; the log's geometry is damaged"
        )
    spread = xy - xy.mean(axis=0)
    sv = np.linalg.svd(spread, compute_uv=False) if n > 1 else np.zeros(1)
    if len(sv) < 2 or sv[1] <= 1e-6 * max(sv[0], 1e-12):
        raise InputError(
            f"{path}: parameters CA_ROTOR0..{n - 1}_PX/PY put every rotor on one line: no moment about that line"
        )


def check_clock(path, name: str, t: np.ndarray) -> None:
    """Refuse a topic whose timestamps ``t`` [s] go back (a clock reset or jump)."""
    back = np.flatnonzero(np.diff(t) < 0.0)
    if back.size:
        i = int(back[0])
        raise InputError(
            f"{path}: {name}'s timestamps go back {t[i] - t[i + 1]:.6g} s at t = {t[i]:.6g} s (message {i + 1}): "
            "the log's clock is not monotonic; unsorted time is refused"
        )


def bracket(t_src: np.ndarray, t0: float, t1: float) -> np.ndarray:
    """The samples of times ``t_src`` an interpolation over [t0, t1] reads: those inside, and one each side."""
    lo = max(int(np.searchsorted(t_src, t0, side="right")) - 1, 0)
    hi = min(int(np.searchsorted(t_src, t1, side="left")) + 1, len(t_src))
    return np.arange(lo, hi)


def check_finite(path, name: str, t_src: np.ndarray, columns: dict[str, np.ndarray], t0: float, t1: float) -> None:
    """Refuse a non-finite value of a topic's ``columns`` (field -> values) among the samples
    used over the airborne stretch [t0, t1] [s]."""
    rows = bracket(t_src, t0, t1)
    for field, values in columns.items():
        v = np.asarray(values, dtype=np.float64)[rows]
        bad = np.flatnonzero(~np.isfinite(v))
        if bad.size:
            k = int(rows[bad[0]])
            what = "NaN" if np.isnan(v[bad[0]]) else ("inf" if v[bad[0]] > 0 else "-inf")
            raise InputError(
                f"{path}: {name}.{field} is {what} at t = {t_src[k]:.6g} s, in the airborne stretch "
                f"({bad.size} such sample(s)): a damaged log"
            )


def check_quaternions(path, name: str, t_src: np.ndarray, q: np.ndarray, t0: float, t1: float) -> None:
    """Refuse quaternions (w, x, y, z) that are not finite or not of unit norm (within 1 %) over
    the airborne stretch [t0, t1] [s]."""
    rows = bracket(t_src, t0, t1)
    check_finite(path, name, t_src, {f"q[{i}]": q[:, i] for i in range(4)}, t0, t1)
    norm = np.linalg.norm(q[rows], axis=1)
    bad = np.flatnonzero(np.abs(norm - 1.0) > 1e-2)
    if bad.size:
        k = int(rows[bad[0]])
        raise InputError(
            f"{path}: {name}.q has norm {norm[bad[0]]:.4g}, not 1, at t = {t_src[k]:.6g} s: not an attitude"
        )


def check_duties(path, u: np.ndarray, names: list[str], *, at: np.ndarray | None = None, hint: str | None = None):
    """Refuse normalised commands ``u`` (L, n) outside [0, 1]: a CSV's rows (``at`` None: row 2 is
    the first) or a log's samples at times ``at`` [s]; ``hint`` says what they might be instead
    (default: PWM in microseconds above 100, rotor speeds above 1).

    Examples
    --------
    >>> check_duties("f.csv", np.array([[0.5], [1500.0]]), ["u1"])
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: f.csv: row 3, column u1: 1500 is outside [0, 1], ... --commands pwm:MIN:MAX, ...
    """
    bad = np.argwhere((u < -1e-6) | (u > 1.0 + 1e-6))
    if not bad.size:
        return
    row, col = (int(x) for x in bad[0])
    value = float(u[row, col])
    if hint is None:
        hint = (
            "PWM in microseconds? read them with --commands pwm:MIN:MAX, e.g. pwm:1000:2000"
            if value > 100.0
            else "rotor speeds? --commands rad/s"
            if value > 1.0
            else ""
        )
    where = f"row {row + 2}, column {names[col]}" if at is None else f"{names[col]} at t = {at[row]:.6g} s"
    raise InputError(
        f"{path}: {where}: {value:g} is outside [0, 1], the range of normalised commands (duties)"
        + (f" ({hint})" if hint else "")
    )
