"""Gain design by pole placement on the double integrator y'' = u (paper section III.B).

The decoupling of eq (15) and the inverse-model position loop of eq (16) reduce every axis
to a double integrator. A PD law u = Kp (r - y) + Kd (r' - y') then gives eq (17),

    y / r = (Kd s + Kp) / (s^2 + Kd s + Kp),      Kd = Kp tau_d,

and a PID law u = Kp e + Ki int(e) + Kd e' the characteristic polynomial
s^3 + Kd s^2 + Kp s + Ki. Poles are s-plane values (the paper's "0.7 and 4.3" are s = -0.7
and s = -4.3); complex poles come in conjugate pairs.

>>> g = pd_from_poles(PAPER_POSITION_POLES)                  # eq (18)
>>> round(g.kp, 2), round(g.kd, 2), round(g.tau_d, 2)
(3.01, 5.0, 1.66)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from quadcruise.checks import describe
from quadcruise.errors import InputError
from quadcruise.fields import Validated, check_value
from quadcruise.fields import unit_field as _f


def python_control():
    """python-control, imported on first use rather than with this module."""
    import control

    return control


__all__ = [
    "PAPER_POSITION_POLES",
    "PDGains",
    "PIDGains",
    "parse_pole",
    "pd_from_poles",
    "pid_from_poles",
    "position_pd_design",
    "altitude_pd_design",
    "attitude_pid_design",
    "loop_transfer",
    "loop_margins",
    "check_with_control",
    "cascade_state_space",
]

PAPER_POSITION_POLES = (-0.7, -4.3)
"""Closed-loop poles of the paper's x/y PD loops [rad/s] (section III.B, eq 18)."""


class _Gains(Validated):
    """Shared behaviour: everything follows from the characteristic polynomial ``_char``.
    Validation and ``units()`` come from :mod:`quadcruise.fields` (messages call the fields
    gains: ``PD gain 'kp' (proportional gain, 1/s^2) must be > 0, got 0.0``)."""

    field_noun = "gain"

    _char: np.ndarray

    @property
    def poles(self) -> np.ndarray:
        """Closed-loop poles on the double integrator, slowest first."""
        p = np.roots(self._char)
        p = np.where(np.abs(p.imag) <= 1e-6 * np.abs(p), p.real, p)
        return np.real_if_close(np.array(sorted(p, key=lambda z: (-z.real, z.imag))))

    def controller(self):
        """C(s) from error to u: ``Kd s + Kp`` (PD) or ``(Kd s^2 + Kp s + Ki) / s`` (PID)."""
        return python_control().tf(self._char[1:], [1.0] + [0.0] * (len(self._char) - 3))

    def closed_loop(self):
        """y/r with the law acting on the error, e.g. ``(Kd s + Kp) / (s^2 + Kd s + Kp)``."""
        return python_control().tf(self._char[1:], self._char)


@dataclass(frozen=True)
class PDGains(_Gains):
    """PD gains for y'' = u: u = kp (r - y) + kd (r' - y'); eq (17) with tau_d = kd / kp.

    Parameters
    ----------
    kp : float
        Proportional gain [1/s^2] (per unit of y), > 0.
    kd : float
        Derivative gain [1/s], >= 0.

    Examples
    --------
    >>> g = PDGains(kp=3.01, kd=5.0)
    >>> [round(float(p), 6) for p in g.poles]
    [-0.7, -4.3]
    >>> round(g.natural_frequency, 3), round(g.damping, 3)
    (1.735, 1.441)
    >>> PDGains(kp=0.0, kd=1.0)
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: PD gain 'kp' (proportional gain, 1/s^2) must be > 0, got 0.0
    """

    kp: float = _f(unit="1/s^2", doc="proportional gain", check="pos")
    kd: float = _f(unit="1/s", doc="derivative gain", check="nonneg")
    name = "PD"

    @property
    def _char(self) -> np.ndarray:
        return np.array([1.0, self.kd, self.kp])

    @property
    def tau_d(self) -> float:
        """Derivative time constant of eq (17) [s]."""
        return self.kd / self.kp

    @property
    def natural_frequency(self) -> float:
        """omega_n = sqrt(kp) [rad/s] of s^2 + 2 zeta omega_n s + omega_n^2."""
        return float(np.sqrt(self.kp))

    @property
    def damping(self) -> float:
        """zeta = kd / (2 sqrt(kp)); above 1 the poles are real."""
        return float(self.kd / (2.0 * np.sqrt(self.kp)))


@dataclass(frozen=True)
class PIDGains(_Gains):
    """PID gains for y'' = u: u = kp e + ki int(e) + kd e'; poles of s^3 + kd s^2 + kp s + ki.

    Parameters
    ----------
    kp : float
        Proportional gain [1/s^2], > 0.
    ki : float
        Integral gain [1/s^3], >= 0.
    kd : float
        Derivative gain [1/s], >= 0.

    Examples
    --------
    >>> PIDGains.units()
    {'kp': '1/s^2', 'ki': '1/s^3', 'kd': '1/s'}
    >>> g = PIDGains(kp=63.0, ki=49.0, kd=15.0)
    >>> [round(float(p), 3) for p in g.poles]
    [-1.0, -7.0, -7.0]
    """

    kp: float = _f(unit="1/s^2", doc="proportional gain", check="pos")
    ki: float = _f(unit="1/s^3", doc="integral gain", check="nonneg")
    kd: float = _f(unit="1/s", doc="derivative gain", check="nonneg")
    name = "PID"

    @property
    def _char(self) -> np.ndarray:
        return np.array([1.0, self.kd, self.kp, self.ki])


def parse_pole(value) -> complex:
    """A pole from a number or a string such as "-0.7" or "-1+2j" ("-1+2i" too).

    Examples
    --------
    >>> parse_pole("-1 + 2i"), parse_pole(-0.7)
    ((-1+2j), (-0.7+0j))
    """
    if isinstance(value, str):
        return complex(value.replace(" ", "").replace("i", "j"))
    return complex(value)


def _fmt(z: complex) -> str:
    return f"{z.real:g}" if z.imag == 0 else f"({z.real:g}{z.imag:+g}j)"


def _char_from_poles(poles, n: int, who: str) -> np.ndarray:
    """Validate ``n`` s-plane poles and return the real monic polynomial with those roots."""
    try:
        p = np.atleast_1d(np.asarray(poles))
    except (TypeError, ValueError):
        p = np.array([None])
    if p.dtype.kind not in "iufc":
        raise InputError(f"{who}: poles must be numbers, got {describe(poles)}")
    p = p.astype(complex)
    if p.ndim != 1 or p.size != n:
        raise InputError(f"{who} needs {n} poles, got {p.size}")
    for z in p:
        if not np.isfinite(z):
            raise InputError(f"{who}: pole {_fmt(z)} is not finite")
        if z.real >= 0:
            hint = f" (did you mean {_fmt(complex(-z.real, z.imag))}?)" if z.real > 0 else ""
            raise InputError(f"{who}: pole {_fmt(z)} is not in the open left half plane{hint}")
    tol = 1e-9 * max(1.0, float(np.max(np.abs(p))))
    left = [z for z in p if abs(z.imag) > tol]
    while left:
        z = left.pop(0)
        j = next((k for k, w in enumerate(left) if abs(w - z.conjugate()) <= tol), None)
        if j is None:
            raise InputError(f"{who}: complex pole {_fmt(z)} has no conjugate {_fmt(z.conjugate())}")
        left.pop(j)
    return np.poly(p).real


def pd_from_poles(poles, source: str = "pd_from_poles") -> PDGains:
    """PD gains placing the closed-loop poles of y'' = u at ``poles`` (two, s-plane).

    s^2 + kd s + kp = (s - p1)(s - p2), so kp = p1 p2 and kd = -(p1 + p2).

    Parameters
    ----------
    poles : sequence of float or complex
        Two closed-loop poles [rad/s] in the open left half plane; a complex one with its
        conjugate.
    source : str
        Where the poles came from, as a message names it (the command line: ``--poles``).

    Returns
    -------
    PDGains
        kp [1/s^2] and kd [1/s].

    Raises
    ------
    InputError
        Not exactly two poles; a pole not finite or with real part >= 0; an unpaired complex pole.

    Examples
    --------
    >>> g = pd_from_poles((-2 + 1j, -2 - 1j))
    >>> g.kp, g.kd
    (5.0, 4.0)
    >>> pd_from_poles((0.7, 4.3))
    Traceback (most recent call last):
    quadcruise.errors.InputError: pd_from_poles: pole 0.7 is not in the open left half plane (did you mean -0.7?)
    """
    c = _char_from_poles(poles, 2, source)
    return PDGains(kp=c[2], kd=c[1])


def pid_from_poles(poles, source: str = "pid_from_poles") -> PIDGains:
    """PID gains placing the closed-loop poles of y'' = u: s^3 + kd s^2 + kp s + ki = (s - p1)(s - p2)(s - p3).

    Examples
    --------
    >>> g = pid_from_poles((-1, -2, -3))
    >>> g.kp, g.ki, g.kd
    (11.0, 6.0, 6.0)
    """
    c = _char_from_poles(poles, 3, source)
    return PIDGains(kp=c[2], ki=c[3], kd=c[1])


def position_pd_design(poles=PAPER_POSITION_POLES) -> PDGains:
    """PD gains of the x/y loops (eq 16); the paper's poles give Kp = 3.01, Kd = 5.0 (eq 18).

    Examples
    --------
    >>> position_pd_design((-1.0, -2.0))
    PDGains(kp=2.0, kd=3.0)
    """
    return pd_from_poles(poles)


def altitude_pd_design(poles=PAPER_POSITION_POLES) -> PDGains:
    """PD gains of the altitude loop z'' = u_z; by default the same poles as x/y.

    Examples
    --------
    >>> round(loop_margins(altitude_pd_design(), 15.0)["phase_margin"], 1)
    65.1
    """
    return pd_from_poles(poles)


ATTITUDE_WN_RATIO = 0.6
"""Natural frequency of the attitude pair as a fraction of the actuator bandwidth."""
ATTITUDE_ZETA = 0.8
"""Damping ratio of the attitude pair."""
ATTITUDE_INTEGRATOR_RATIO = 1.0 / 30.0
"""Integrator pole as a fraction of the actuator bandwidth."""


def attitude_pid_design(actuator_bandwidth: float = 15.0) -> PIDGains:
    """PID gains of a decoupled attitude loop phi'' = U2* (eq 15): poles at 0.6 w (zeta 0.8) and w / 30.
    Why these: docs/paper.md, "Attitude gains".

    Parameters
    ----------
    actuator_bandwidth : float
        The rotor lag's bandwidth w [rad/s] (15: the paper's vehicle).

    Returns
    -------
    PIDGains
        kp [1/s^2], ki [1/s^3], kd [1/s].

    Examples
    --------
    >>> g = attitude_pid_design()
    >>> round(g.kp, 2), round(g.ki, 2), round(g.kd, 2)
    (88.2, 40.5, 14.9)
    >>> round(loop_margins(g, 15.0)["phase_margin"], 1)
    24.5
    """
    w = check_value(
        "attitude_pid_design argument 'actuator_bandwidth' (rotor lag bandwidth, rad/s)", actuator_bandwidth, "pos"
    )
    wn, zeta = ATTITUDE_WN_RATIO * w, ATTITUDE_ZETA
    pair = complex(-zeta * wn, wn * np.sqrt(1.0 - zeta**2))
    return pid_from_poles([pair, pair.conjugate(), -ATTITUDE_INTEGRATOR_RATIO * w])


def cascade_state_space(position: PDGains, attitude: PIDGains, actuator_bandwidth: float = 15.0, g: float = 9.81):
    """The x loop of the paper's controller linearised about hover, from x_r to x (states: docs/paper.md,
    "Gain design").

    Examples
    --------
    >>> from quadcruise.control.design import position_pd_design
    >>> sys = cascade_state_space(position_pd_design(), attitude_pid_design())
    >>> bool(np.all(sys.poles().real < 0)), round(float(sys.dcgain()), 6)
    (True, 1.0)
    """
    w = float(actuator_bandwidth)
    kp, kd = position.kp, position.kd
    kpa, kia, kda = attitude.kp, attitude.ki, attitude.kd
    theta_d = np.array([-kp, -kd, 0.0, 0.0, 0.0, 0.0]) / g  # theta_d as a row over the states
    e = np.eye(6)
    u_star = kpa * (theta_d - e[2]) + kia * e[5] - kda * e[3]
    A = np.zeros((6, 6))
    A[0, 1], A[1, 2], A[2, 3], A[3, 4] = 1.0, g, 1.0, 1.0
    A[4] = w * u_star - w * e[4]
    A[5] = theta_d - e[2]
    B = np.zeros((6, 1))
    B[4, 0] = w * kpa * kp / g
    B[5, 0] = kp / g
    return python_control().ss(A, B, e[:1], 0.0)


def loop_transfer(gains: PDGains | PIDGains, actuator_bandwidth: float | None = None):
    """Open loop L(s) = C(s) w/(s+w) / s^2 (without the lag factor when the bandwidth is None).

    Examples
    --------
    >>> L = loop_transfer(PDGains(kp=1.0, kd=2.0))
    >>> L.num[0][0].tolist(), L.den[0][0].tolist()
    ([2.0, 1.0], [1.0, 0.0, 0.0])
    """
    s = python_control().tf("s")
    lag = 1 if actuator_bandwidth is None else actuator_bandwidth / (s + actuator_bandwidth)
    return gains.controller() * lag / s**2


def loop_margins(gains: PDGains | PIDGains, actuator_bandwidth: float | None = 15.0) -> dict:
    """Stability margins of :func:`loop_transfer` by ``control.stability_margins``.

    Examples
    --------
    >>> m = loop_margins(position_pd_design(), None)
    >>> round(m["phase_margin"], 1), m["gain_margin"], m["stable"]
    (83.2, inf, True)
    """
    L = loop_transfer(gains, actuator_bandwidth)
    gm, pm, _, wpc, wgc, _ = python_control().stability_margins(L)
    stable = bool(np.all(python_control().feedback(L, 1).poles().real < 0))
    return {
        "gain_margin": float(gm),
        "phase_margin": float(pm),
        "phase_crossover": float(wpc),
        "gain_crossover": float(wgc),
        "stable": stable,
    }


def check_with_control(gains: PDGains | PIDGains) -> dict:
    """Gains checked by python-control's ``place`` (``acker`` for repeated poles) on the double integrator.

    Examples
    --------
    >>> r = check_with_control(position_pd_design())
    >>> r["place_gain"].round(6).tolist(), r["gain_error"] < 1e-9
    ([3.01, 5.0], True)
    >>> round(r["step_info"]["Overshoot"], 1)
    8.0
    """
    n = len(gains._char) - 1
    A, B = np.eye(n, k=1), np.eye(n)[:, -1:]
    sys = python_control().ss(A, B, np.eye(n)[-2:-1], 0)
    poles = gains.poles
    try:
        K = np.asarray(python_control().place(sys.A, sys.B, poles)).ravel()
    except ValueError:
        K = np.asarray(python_control().acker(sys.A, sys.B, poles)).ravel()
    want = gains._char[:0:-1]
    cl = np.linalg.eigvals(sys.A - sys.B @ K[None, :])
    dist = np.abs(cl[:, None] - poles[None, :])
    return {
        "place_gain": K,
        "gain_error": float(np.max(np.abs(K - want)) / np.max(np.abs(want))),
        "closed_loop_poles": cl,
        "pole_error": float(max(dist.min(0).max(), dist.min(1).max())),
        "step_info": python_control().step_info(gains.closed_loop()),
    }
