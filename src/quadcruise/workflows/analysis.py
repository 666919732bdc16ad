"""Linear analysis of any closed loop about hover: poles, loop margins, Bode plots.

:func:`linearize` differentiates one control period of the engine (the controller called
once, its duties clipped and held, the plant integrated by RK4 over ``dt``) by central
differences and hands it to python-control as the discrete system ``control.ss(A, B, C, D,
dt)``: the state is the plant's 16 states then the controller's memory, the inputs are the
set-points x_r, y_r, z_r, psi_r (their rates stay zero, as in a step), the outputs x, y, z,
phi, theta, psi. Any controller compiled with ``layout.CONTROLLER_SIG`` works: it is only
called. Hover must be an equilibrium of that map, else :class:`HoverError` names the state
that drifts. Poles in rad/s are s = log(z) / dt (:meth:`Linearization.poles_continuous`).

**Loops and where they are broken.** At hover the closed loop splits into four loops: the
connected components of A once the rotor thrusts are written as U1..U4 of eqs (1)-(4).
For margins one loop is broken, the others closed, at the plant input (``at="input"``):
on the generalized input that drives it, before the rotor lag: U3 for x (through pitch), U2
for y (roll), U1 for z, U4 for yaw. There a thrust-gain, inertia or motor-lag error of the
real vehicle enters; for z and yaw it is the break of :func:`quadcruise.control.design.loop_margins`.
The x and y input margins cover the attitude loop *and* the position loop around it.
``at="output"`` breaks instead at the position (or yaw) measurement the controller sees,
velocity and attitude feedback closed: the outer loop's own margins.

>>> lin = linearize("nlpd")
>>> lin.stable, sorted(lin.loops)
(True, ['x', 'y', 'yaw', 'z'])
>>> [round(float(p.real), 2) for p in lin.loop_poles("x") if p.imag == 0]
[-0.47, -0.66]
>>> round(loop_margins(lin, "z")["phase_margin"], 1)     # design.loop_margins: 65.1 (continuous)
65.0
"""

from __future__ import annotations

import math
import textwrap
import warnings
from collections.abc import Callable
from dataclasses import dataclass

import control
import numpy as np
import scipy.linalg
from scipy.sparse.csgraph import connected_components

from quadcruise import checks
from quadcruise.errors import InputError
from quadcruise.layout import (
    CMD_FLAGS,
    CMD_SIZE,
    EXT_E1,
    EXT_SIZE,
    F1,
    P_D,
    P_G,
    P_K,
    P_M,
    REF_NAMES,
    REF_Z,
    STATE_NAMES,
    STATE_SIZE,
    Z,
)
from quadcruise.model.actuators import mix
from quadcruise.model.vehicle import Vehicle

INPUTS = ("x_ref", "y_ref", "z_ref", "psi_ref")
OUTPUTS = ("x", "y", "z", "phi", "theta", "psi")
LOOPS = {"x": (2, "x"), "y": (1, "y"), "z": (0, "z"), "yaw": (3, "psi")}
"""Each loop's generalized input (0..3: U1..U4) and measured output (a state name)."""
DESIGN = {"x": "position", "y": "position", "z": "altitude", "yaw": "yaw"}
"""The controller attribute with each loop's design gains (``.poles``), where it has one."""


class HoverError(InputError):
    """The controller does not hold hover: there is no equilibrium to linearise about."""


def _period(x, u, vp, dt, n_sub):
    """One control period as the engine integrates it (:func:`quadcruise.sim.engine.rk4_step`,
    n_sub substeps, duties held) in still air with healthy rotors and the paper's
    kinematics (the exact ones agree to first order at hover): the next state."""
    from quadcruise.sim.engine import WORK_ROWS, rk4_step

    ext = np.zeros(EXT_SIZE)
    ext[EXT_E1:EXT_E1 + 4] = 1.0
    x, u = np.array(x, dtype=float), np.ascontiguousarray(u, dtype=float)
    work = np.empty((WORK_ROWS, STATE_SIZE))
    for _ in range(n_sub):
        rk4_step(x, u, vp, ext, False, dt / n_sub, work, True)
    return x


def _jacobian(f, v0, eps):
    """Central differences of f at v0, step eps * max(1, |v_i|)."""
    steps = eps * np.maximum(1.0, np.abs(v0))
    return np.array([(f(v0 + h * e) - f(v0 - h * e)) / (2.0 * h) for h, e in zip(steps, np.eye(v0.size))]).T


def _s_plane(z, dt):
    """s = log(z) / dt, real where the imaginary part is rounding (-inf for a pole at z = 0,
    a mode that dies in one period), and the order slowest first."""
    z = np.asarray(z, complex)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(np.abs(z) < 1e-300, -np.inf, np.log(np.where(np.abs(z) < 1e-300, 1.0, z)) / dt)
    s = np.where(np.abs(s.imag) < 1e-9 * np.maximum(1.0, np.abs(s)), s.real, s)
    return np.lexsort((s.imag, -s.real)), s


@dataclass(frozen=True)
class Linearization:
    """The discrete closed loop about hover, ``sys``, and the pieces it is composed of.

    :func:`linearize` builds it. With x the plant's 16 states, m the controller's memory
    and u the four duties, over one control period: x+ = plant_A x + plant_B u,
    u = K_state x + K_memory m, m+ = H_state x + H_memory m (plus the set-point terms).

    Parameters
    ----------
    sys : control.StateSpace
        The discrete closed loop: states x then m, inputs :data:`INPUTS` [m, rad],
        outputs :data:`OUTPUTS` [m, rad], sampling time ``dt``.
    dt : float
        Control period [s].
    controller : Controller
        The controller linearised.
    plant_A : ndarray, shape (16, 16)
        d x+ / d x of the plant over one period, duties held.
    plant_B : ndarray, shape (16, 4)
        d x+ / d u [state unit per unit duty].
    K_state : ndarray, shape (4, 16)
        d u / d x of the controller.
    K_memory : ndarray, shape (4, C)
        d u / d m.
    H_state : ndarray, shape (C, 16)
        d m+ / d x.
    H_memory : ndarray, shape (C, C)
        d m+ / d m.
    mixer : ndarray, shape (4, 4)
        U1..U4 = mixer @ u ([N], [N], [N], [N m] per unit duty).
    loops : dict of str to ndarray
        Each loop's (``x``, ``y``, ``z``, ``yaw``) state indices.
    residual : float
        The largest drift rate at hover [state unit/s].
    """

    sys: control.StateSpace
    dt: float
    controller: object
    plant_A: np.ndarray
    plant_B: np.ndarray
    K_state: np.ndarray
    K_memory: np.ndarray
    H_state: np.ndarray
    H_memory: np.ndarray
    mixer: np.ndarray
    loops: dict
    residual: float

    @property
    def stable(self) -> bool:
        """True if all discrete poles lie strictly inside the unit circle."""
        return bool(np.max(np.abs(self.poles())) < 1.0)

    def poles(self) -> np.ndarray:
        """Discrete-time poles (z-plane).

        Returns
        -------
        ndarray of complex
            The eigenvalues of ``sys.A`` [-].
        """
        return np.linalg.eigvals(self.sys.A)

    def poles_continuous(self) -> np.ndarray:
        """Poles in rad/s, s = log(z) / dt (exact for the sampled modes), slowest first.

        Returns
        -------
        ndarray of complex
            s [rad/s]; real where the imaginary part is rounding, -inf for a pole at z = 0
            (a mode that dies in one period).
        """
        order, s = _s_plane(self.poles(), self.dt)
        return s[order]

    def loop_poles(self, loop: str) -> np.ndarray:
        """Poles [rad/s] of one loop's block of A, slowest first.

        Parameters
        ----------
        loop : str
            ``"x"``, ``"y"``, ``"z"`` or ``"yaw"``.

        Returns
        -------
        ndarray of complex
            s [rad/s], as :meth:`poles_continuous`.
        """
        return self.loop_modes(loop)[0]

    def loop_modes(self, loop: str) -> tuple[np.ndarray, np.ndarray]:
        """One loop's poles, slowest first, and each one's weight in the loop's step response.

        Parameters
        ----------
        loop : str
            ``"x"``, ``"y"``, ``"z"`` or ``"yaw"``.

        Returns
        -------
        poles : ndarray of complex
            s [rad/s], as :meth:`poles_continuous`.
        weights : ndarray
            Each pole's weight |a_i| / |Re s_i| in the step response of the loop's set-point
            to its output (a_i: the mode's amplitude; the weight is the integral of
            |a_i exp(s_i t)| [output unit s]; the largest marks the dominant pole; inf for a
            marginal mode).
        """
        idx, state = self.loops[_check_loop(loop)], LOOPS[loop][1]
        S = _to_generalized(self.sys.nstates, self.mixer)
        Si = np.linalg.inv(S)
        z, V = np.linalg.eig((S @ self.sys.A @ Si)[np.ix_(idx, idx)])
        b = (S @ self.sys.B)[idx, INPUTS.index(f"{state}_ref")]
        c = (self.sys.C @ Si)[OUTPUTS.index(state), idx]
        order, s = _s_plane(z, self.dt)
        with np.errstate(divide="ignore", invalid="ignore"):      # inf for a marginal mode
            weight = np.abs((c @ V) * np.linalg.solve(V, b) / (1.0 - z)) / np.abs(s.real)
        return s[order], weight[order]

    def continuous(self) -> control.StateSpace:
        """The continuous system whose zero-order-hold sampling is ``sys``.

        logm([[A, B], [0, I]]) / dt = [[Ac, Bc], [0, 0]].

        Returns
        -------
        control.StateSpace
            Continuous time, the same states, inputs and outputs as ``sys``.

        Raises
        ------
        InputError
            If the loop has purely discrete modes (poles at z = 0 or on the negative real
            axis), which have no continuous equivalent.
        """
        n, m = self.sys.B.shape
        z = self.poles()
        if np.any((np.abs(z.imag) < 1e-12) & (z.real <= 1e-12)):
            raise InputError("the loop has purely discrete modes (poles at z = 0 or on the negative real "
                             "axis, e.g. a one-period memory): it has no continuous equivalent")
        L = scipy.linalg.logm(np.block([[self.sys.A, self.sys.B], [np.zeros((m, n)), np.eye(m)]])).real / self.dt
        return control.ss(L[:n, :n], L[:n, n:], self.sys.C, self.sys.D, inputs=INPUTS, outputs=OUTPUTS,
                          states=list(self.sys.state_labels))


def _check_loop(loop: str) -> str:
    if loop not in LOOPS:
        raise InputError(f"unknown loop {loop!r}; choose one of {', '.join(LOOPS)}")
    return loop


def _as_controller(controller):
    if isinstance(controller, str):
        from quadcruise.control import controller_from_name
        return controller_from_name(controller)
    if isinstance(controller, type):
        checks.fail("linearize()", "controller", controller, "a controller name or object")
    missing = [m for m in ("function", "gains", "memory") if not hasattr(controller, m)]
    if missing:
        raise InputError(f"controller must be a name or have .function, .gains() and .memory(); "
                         f"{type(controller).__name__} lacks {', '.join(missing)}")
    return controller


MIN_DT = 1e-9
"""The shortest control period :func:`linearize` takes [s]: at 1e-12 s the poles z = exp(s dt) are
within rounding of 1, and the s-plane poles computed from them are noise."""


def linearize(controller="nlpd", vehicle: Vehicle | None = None, *, dt: float = 1e-3, hover_z: float = 1.0,
              eps: float = 1e-6, max_step: float | None = None, memory=None, settle: int = 1,
              tol: float = 1e-6, progress: Callable[[int, int], None] | None = None) -> Linearization:
    """Linearise plant + controller over one control period ``dt`` about hover at ``hover_z``.

    Parameters
    ----------
    controller : Controller or str
        A controller name, or anything with ``.function`` (compiled, ``CONTROLLER_SIG``),
        ``.gains()``, ``.memory()``.
    vehicle : Vehicle, optional
        One vehicle (Table I by default); the controller sees the same parameters.
    dt : float
        Control period [s], as in ``fly``.
    hover_z : float
        Hover altitude [m] (x = y = yaw = 0, every rotor at m g / 4).
    eps : float
        Relative central-difference step [-].
    max_step : float, optional
        Longest RK4 substep [s]; ``dt`` by default.
    memory : array, optional
        The controller's memory to start from; ``controller.memory()`` by default.
    settle : int
        Periods the controller is first called at hover, its memory kept: a controller may
        initialise memory in its first period (a first-call flag, a derivative's last sample).
    tol : float
        Largest drift rate [unit/s] of any state or memory entry that still counts as hover.
    progress : callable, optional
        ``progress(done, total)`` at the start and after each of its three steps: hover
        checked, the controller differentiated, the plant differentiated.

    Returns
    -------
    Linearization
        The discrete closed loop and its pieces.

    Raises
    ------
    HoverError
        Hover is not an equilibrium of the period map, or a duty sits on its clip.

    Examples
    --------
    >>> lin = linearize("nlpd")
    >>> lin.sys.nstates, lin.sys.ninputs, lin.sys.noutputs, lin.sys.dt
    (19, 4, 6, 0.001)
    >>> bool(lin.residual < 1e-9), lin.sys.state_labels[-3:]
    (True, ['mem0', 'mem1', 'mem2'])
    """
    w = "linearize()"                                # every argument checked before any work
    controller = _as_controller(controller)          # (its function may be plain Python: it is called here)
    vehicle = checks.instance(w, "vehicle", vehicle, Vehicle) or Vehicle.paper()
    dt = checks.number(w, "dt", dt, "pos", unit="s")
    hover_z = checks.number(w, "hover_z", hover_z, unit="m")
    eps = checks.number(w, "eps", eps, "pos")
    max_step = checks.number(w, "max_step", max_step, "pos", unit="s", optional=True)
    settle = checks.whole(w, "settle", settle)
    tol = checks.number(w, "tol", tol, "pos")
    checks.callback(w, "progress", progress)
    if vehicle.batch_size not in (None, 1):
        raise InputError(f"linearize takes one vehicle, got a batch of {vehicle.batch_size}")
    if not (math.isfinite(dt) and dt > 0):
        raise InputError(f"dt must be a positive number of seconds, got {dt!r}")
    if dt < MIN_DT:
        raise InputError(f"dt = {dt:g} s is below {MIN_DT:g} s: the discrete poles would lie within rounding of 1 "
                         "and read as unstable; linearise at a real control period")
    vp = np.ascontiguousarray(vehicle.rows()[0])
    gains = np.ascontiguousarray(controller.gains(), dtype=float)
    mem0 = np.array(controller.memory() if memory is None else memory, dtype=float).ravel()
    n, C = STATE_SIZE + mem0.size, mem0.size
    n_sub = max(1, math.ceil(dt / (max_step or dt) - 1e-9))
    x0, ref0 = np.zeros(STATE_SIZE), np.zeros(len(REF_NAMES))
    x0[Z], x0[F1:F1 + 4], ref0[REF_Z] = hover_z, vp[P_M] * vp[P_G] / 4.0, hover_z
    cols = [REF_NAMES.index(name) for name in INPUTS]
    step = _steps(progress, 3)

    def ctrl(v):                      # (x, memory, set-points) -> (duties, next memory, flags)
        ref, mem, cmd = ref0.copy(), v[STATE_SIZE:n].copy(), np.zeros(CMD_SIZE)
        ref[cols] = v[n:]
        controller.function(0.0, dt, np.ascontiguousarray(v[:STATE_SIZE]), ref, vp, gains, mem, cmd)
        return np.concatenate([cmd[:4], mem, cmd[CMD_FLAGS:CMD_FLAGS + 1]])

    for _ in range(settle):
        mem0 = ctrl(np.concatenate([x0, mem0, ref0[cols]]))[4:4 + C]
    v0 = np.concatenate([x0, mem0, ref0[cols]])
    out0 = ctrl(v0)
    u0 = out0[:4]
    drift = np.concatenate([_period(x0, np.clip(u0, 0.0, 1.0), vp, dt, n_sub) - x0, out0[4:4 + C] - mem0]) / dt
    names = list(STATE_NAMES) + [f"mem{i}" for i in range(C)]
    if not np.all(np.abs(drift) <= tol):
        i = int(np.argmax(np.where(np.isfinite(drift), np.abs(drift), np.inf)))
        who = getattr(controller, "name", "the controller")
        raise HoverError(f"{who} does not hold hover at z = {hover_z:g} m: '{names[i]}' moves at {drift[i]:.3g} "
                         f"per second (tolerance {tol:g}), so there is no equilibrium to linearise about")
    if np.any(u0 <= 0.0) or np.any(u0 >= 1.0):
        raise HoverError(f"a hover duty sits on its clip to [0, 1] ({np.round(u0, 4).tolist()}): "
                         f"the loop is not differentiable there")
    if out0[-1] != 0.0:
        warnings.warn(f"the controller flags a limit at hover (flags {out0[-1]:g})", stacklevel=2)
    step()

    # the period map's Jacobian by the chain rule: controller, then plant (a duty clip is inactive)
    G = _jacobian(lambda v: ctrl(v)[:4 + C], v0, eps)
    step()
    P = _jacobian(lambda v: _period(v[:STATE_SIZE], v[STATE_SIZE:], vp, dt, n_sub), np.r_[x0, u0], eps)
    step()
    Ap, Bp = P[:, :STATE_SIZE], P[:, STATE_SIZE:]
    (Kx, Km, Kr), (Hx, Hm, Hr) = np.split(G[:4], [STATE_SIZE, n], axis=1), np.split(G[4:], [STATE_SIZE, n], axis=1)
    A = np.block([[Ap + Bp @ Kx, Bp @ Km], [Hx, Hm]])
    Cy = np.eye(n)[[STATE_NAMES.index(name) for name in OUTPUTS]]
    sys = control.ss(A, np.vstack([Bp @ Kr, Hr]), Cy, 0.0, dt, inputs=INPUTS, outputs=OUTPUTS, states=names)
    mixer = vp[P_K] * np.array([mix(*row, vp[P_D]) for row in np.eye(4)]).T
    return Linearization(sys, float(dt), controller, Ap, Bp, Kx, Km, Hx, Hm, mixer, _loops(A, mixer),
                         float(np.max(np.abs(drift))))


def _to_generalized(n, mixer):
    """The change of state that replaces the rotor thrusts F1..F4 by U1..U4 (up to scale)."""
    S = np.eye(n)
    S[F1:F1 + 4, F1:F1 + 4] = mixer / mixer[0, 0]
    return S


def _loops(A, mixer):
    """Each loop's state indices: the connected component of A (in U1..U4 coordinates, where
    the loops decouple at hover) that holds the loop's measured output."""
    S = _to_generalized(A.shape[0], mixer)
    At = np.abs(S @ A @ np.linalg.inv(S) - np.eye(A.shape[0]))
    _, label = connected_components(At > 1e-9 * At.max(), directed=False)
    return {loop: np.flatnonzero(label == label[STATE_NAMES.index(state)]) for loop, (_, state) in LOOPS.items()}


def loop_transfer(lin: Linearization, loop: str = "x", at: str = "input") -> control.StateSpace:
    """The discrete loop transfer L(z) of one loop broken at the plant input or output.

    Parameters
    ----------
    lin : Linearization
        The closed loop.
    loop : str
        ``"x"``, ``"y"``, ``"z"`` or ``"yaw"``; the others stay closed.
    at : str
        ``"input"``: at the loop's generalized input U1..U4; ``"output"``: at the position
        (or yaw) measurement the controller sees (see the module).

    Returns
    -------
    control.StateSpace
        L(z), one input and one output, sampling time ``lin.dt``, signed for negative
        feedback (the closed loop is L / (1 + L)).
    """
    u_idx, state = LOOPS[_check_loop(loop)]
    Ap, Bp, Kx, Km, Hx, Hm = lin.plant_A, lin.plant_B, lin.K_state, lin.K_memory, lin.H_state, lin.H_memory
    C = Hm.shape[0]
    if at == "input":                # w replaces the controller's U_j at the plant input
        Bu, KU, KmU = Bp @ np.linalg.inv(lin.mixer), lin.mixer @ Kx, lin.mixer @ Km
        e = np.eye(4)[:, [u_idx]]
        keep = np.eye(4) - e @ e.T
        A = np.block([[Ap + Bu @ keep @ KU, Bu @ keep @ KmU], [Hx, Hm]])
        B, Cl = np.vstack([Bu @ e, np.zeros((C, 1))]), -np.hstack([KU[u_idx], KmU[u_idx]])[None, :]
    elif at == "output":             # w replaces the measured output the controller sees
        e = np.eye(STATE_SIZE)[:, [STATE_NAMES.index(state)]]
        keep = np.eye(STATE_SIZE) - e @ e.T
        A = np.block([[Ap + Bp @ Kx @ keep, Bp @ Km], [Hx @ keep, Hm]])
        B, Cl = np.vstack([Bp @ Kx @ e, Hx @ e]), -np.hstack([e.T, np.zeros((1, C))])
    else:
        raise InputError(f"at must be 'input' or 'output', got {at!r}")
    return control.ss(A, B, Cl, 0.0, lin.dt)


def _steps(progress: Callable[[int, int], None] | None, total: int) -> Callable[[], None]:
    """``progress(0, total)`` now, and a function that reports one more step done each call."""
    done = [0]

    def step() -> None:
        done[0] += 1
        if progress is not None:
            progress(done[0], total)

    if progress is not None:
        progress(0, total)
    return step


def _omega(dt, n=2000):
    return np.logspace(-3, math.log10(0.999 * math.pi / dt), n)


def loop_margins(lin: Linearization, loop: str = "x", at: str = "input") -> dict:
    """Margins of :func:`loop_transfer` by ``control.stability_margins``.

    They are read from its frequency response up to the Nyquist frequency (the polynomial
    method is ill-conditioned for a 19-state loop with poles crowded near z = 1).

    Parameters
    ----------
    lin : Linearization
        The closed loop.
    loop : str
        ``"x"``, ``"y"``, ``"z"`` or ``"yaw"``.
    at : str
        Where the loop is broken: ``"input"`` or ``"output"`` (see :func:`loop_transfer`).

    Returns
    -------
    dict
        ``phase_margin`` [deg] at ``gain_crossover`` [rad/s]; ``gain_margin`` [-] (the one
        python-control picks, nearest 1) at ``phase_crossover`` [rad/s]; ``gain_increase``
        [-] (the smallest destabilising factor > 1, inf if none) at
        ``gain_increase_frequency`` [rad/s] and ``gain_decrease`` [-] (the largest < 1, 0 if
        none) at ``gain_decrease_frequency`` [rad/s], and both in decibels,
        ``gain_increase_db`` (> 0, inf if none) and ``gain_decrease_db`` (< 0, -inf if none);
        ``stability_margin`` (least distance of L to -1) and its frequency
        ``stability_margin_frequency`` [rad/s]; ``open_loop_unstable_poles`` (of L; when
        not 0 the margins alone do not tell stability). A loop with a ``gain_decrease`` is
        conditionally stable: it is stable at its own gain and goes unstable if the gain
        falls by that factor (a PID's integral on a double integrator makes the phase
        cross -180 deg below the gain crossover), as well as if it rises by
        ``gain_increase``.

    Examples
    --------
    >>> m = loop_margins(linearize("nlpd"), "yaw")          # design.loop_margins: 24.5 deg
    >>> round(m["phase_margin"], 1), round(m["gain_crossover"], 1)
    (24.1, 12.5)
    """
    w, L = _omega(lin.dt), loop_transfer(lin, loop, at)
    r = control.frequency_response(L, w).complex.ravel()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        gms, pms, sms, wpcs, wgcs, wsms = (np.atleast_1d(a) for a in control.stability_margins(
            (np.abs(r), np.degrees(np.unwrap(np.angle(r))), w), returnall=True))
    with np.errstate(divide="ignore"):
        g = int(np.argmin(np.abs(np.log(gms)))) if gms.size and not np.isinf(gms).all() else None
    p, s = (int(np.argmin(np.abs(pms))) if pms.size else None), (int(np.argmin(sms)) if sms.size else None)
    up, down = np.flatnonzero(gms > 1), np.flatnonzero(gms < 1)
    up = up[np.argmin(gms[up])] if up.size else None
    down = down[np.argmax(gms[down])] if down.size else None
    increase, decrease = (math.inf if up is None else float(gms[up])), (0.0 if down is None else float(gms[down]))
    return {"phase_margin": math.inf if p is None else float(pms[p]),
            "gain_crossover": math.nan if p is None else float(wgcs[p]),
            "gain_margin": math.inf if g is None else float(gms[g]),
            "phase_crossover": math.nan if g is None else float(wpcs[g]),
            "gain_increase": increase,
            "gain_increase_frequency": math.nan if up is None else float(wpcs[up]),
            "gain_increase_db": _db(increase),
            "gain_decrease": decrease,
            "gain_decrease_frequency": math.nan if down is None else float(wpcs[down]),
            "gain_decrease_db": _db(decrease),
            "stability_margin": math.nan if s is None else float(sms[s]),
            "stability_margin_frequency": math.nan if s is None else float(wsms[s]),
            "open_loop_unstable_poles": int(np.sum(np.abs(np.linalg.eigvals(L.A)) > 1.0 + 1e-9))}


def _db(factor: float) -> float:
    """20 log10(factor) [dB]; -inf for 0."""
    return -math.inf if factor == 0.0 else 20.0 * math.log10(factor)


MIN_PHASE_MARGIN_DEG = 30.0
"""A phase margin below this [deg] is flagged: the usual floor for a loop that must tolerate
unmodelled lag (delay, a slower motor) without ringing."""
MIN_GAIN_MARGIN_DB = 6.0
"""A gain margin within this [dB] of 0 dB, up or down, is flagged: a loop gain error of a
factor 2 (thrust coefficient, inertia, battery sag) must not destabilise it."""


def low_margins(m: dict) -> list[str]:
    """What is short in one loop's margins (:func:`loop_margins`), in words.

    Flagged: a phase margin below :data:`MIN_PHASE_MARGIN_DEG`, a gain margin up or down
    within :data:`MIN_GAIN_MARGIN_DB` of 0 dB.

    Parameters
    ----------
    m : dict
        What :func:`loop_margins` returns.

    Returns
    -------
    list of str
        One phrase per margin that is short (empty if none), e.g. ``"PM 18.1 deg < 30 deg"``.

    Examples
    --------
    >>> low_margins({"phase_margin": 18.1, "gain_increase_db": 38.2, "gain_decrease_db": -3.98})
    ['PM 18.1 deg < 30 deg', 'GM down -3.98 dB > -6 dB']
    """
    out = []
    if m["phase_margin"] < MIN_PHASE_MARGIN_DEG:
        out.append(f"PM {m['phase_margin']:.3g} deg < {MIN_PHASE_MARGIN_DEG:g} deg")
    if m["gain_increase_db"] < MIN_GAIN_MARGIN_DB:
        out.append(f"GM up {m['gain_increase_db']:+.3g} dB < {MIN_GAIN_MARGIN_DB:+g} dB")
    if m["gain_decrease_db"] > -MIN_GAIN_MARGIN_DB:
        out.append(f"GM down {m['gain_decrease_db']:+.3g} dB > {-MIN_GAIN_MARGIN_DB:+g} dB")
    return out


def unwrapped_phase(response, start: float = 0.0) -> np.ndarray:
    """The phase of a frequency response [deg], continuous over frequency (``numpy.unwrap``),
    shifted by whole turns so that it starts (at the lowest frequency) nearest ``start``.

    A phase wrapped to a fixed 360 deg window jumps where it leaves the window and hides how
    far a loop lags; unwrapped, a curve reads straight off the plot, and the -180 deg lines
    (every 360 deg) mark where a margin is read.

    Parameters
    ----------
    response : array_like of complex
        The response at increasing frequencies.
    start : float
        The phase [deg] the first point is brought nearest to: 0 for a closed loop (unit DC
        gain), -180 for a loop transfer (python-control's ``bode_plot`` default, its
        ``initial_phase``).

    Returns
    -------
    ndarray
        Phase [deg], no step between neighbours larger than 180 deg.

    Examples
    --------
    >>> r = np.exp(-1j * np.radians([170.0, 190.0, 350.0, 370.0]))
    >>> unwrapped_phase(r).round(6).tolist(), unwrapped_phase(-r, start=-180.0).round(6).tolist()
    ([-170.0, -190.0, -350.0, -370.0], [-350.0, -370.0, -530.0, -550.0])
    """
    phase = np.degrees(np.unwrap(np.angle(np.asarray(response, complex))))
    return phase - 360.0 * np.round((phase[0] - start) / 360.0)


def _margin_label(m: dict) -> str:
    """``PM 18.1° @ 10.8 rad/s (< 30°), GM down -3.98 dB @ 7.07 rad/s (> -6 dB), up +38.2 dB @ 300 rad/s``:
    each margin with its unit and frequency, a short one marked; one without crossover left out."""
    parts = []
    if math.isfinite(m["phase_margin"]) and math.isfinite(m["gain_crossover"]):
        short = f" (< {MIN_PHASE_MARGIN_DEG:g}°)" if m["phase_margin"] < MIN_PHASE_MARGIN_DEG else ""
        parts.append(f"PM {m['phase_margin']:.3g}° @ {m['gain_crossover']:.3g} rad/s{short}")
    gms = []
    if math.isfinite(m["gain_decrease_db"]):
        short = f" (> {-MIN_GAIN_MARGIN_DB:+g} dB)" if m["gain_decrease_db"] > -MIN_GAIN_MARGIN_DB else ""
        gms.append(f"down {m['gain_decrease_db']:+.3g} dB @ {m['gain_decrease_frequency']:.3g} rad/s{short}")
    if math.isfinite(m["gain_increase_db"]):
        short = f" (< {MIN_GAIN_MARGIN_DB:+g} dB)" if m["gain_increase_db"] < MIN_GAIN_MARGIN_DB else ""
        gms.append(f"up {m['gain_increase_db']:+.3g} dB @ {m['gain_increase_frequency']:.3g} rad/s{short}")
    if gms:
        parts.append("GM " + ", ".join(gms))
    return ", ".join(parts) or "no crossover"


def _nearest_minus_180(phase: float) -> float:
    """The line -180 + 360 k [deg] nearest ``phase``: where a margin is read on an unwrapped phase."""
    return -180.0 + 360.0 * round((phase + 180.0) / 360.0)


def bode(lin: Linearization, *, loops: bool = False, omega=None, at: str = "input",
         progress: Callable[[int, int], None] | None = None):
    """Bode plots of the closed loop and, optionally, of the loop transfers with their margins.

    Parameters
    ----------
    lin : Linearization
        The closed loop.
    loops : bool
        Add a second column of the loop transfers (broken ``at``), with their margins
        (:func:`loop_margins`) marked and named: the phase margin as a segment from the
        -180 deg line up to the phase at the gain crossover (a dot there on the 0 dB line
        too), each gain margin (down and up) as a segment from the 0 dB line to the magnitude
        at its phase crossover (a square there on the -180 deg line too), all with units and
        frequencies in the legend ("PM 18.1° @ 10.8 rad/s (< 30°), GM down -3.98 dB @ 7.07
        rad/s (> -6 dB), up +38.2 dB @ 300 rad/s": the loop is stable and stays so while its
        gain falls by less than 3.98 dB or rises by less than 38.2 dB; a margin short of
        30 deg or 6 dB is marked). y's margins are x's for a symmetric vehicle and are then
        not marked twice.
    omega : array_like, optional
        Frequencies [rad/s]; by default 800 from 0.01 rad/s to 0.9 of the Nyquist frequency
        pi / dt (closer to it the sampling zeros near z = -1 turn the phase by half a turn
        between two samples, which no unwrapping can tell from a jump).
    at : str
        Where the loops are broken: ``"input"`` or ``"output"`` (see :func:`loop_transfer`).
    progress : callable, optional
        ``progress(done, total)`` at the start and after each of the four loops drawn.

    Returns
    -------
    matplotlib.figure.Figure
        Magnitude [dB] above phase [deg] against frequency [rad/s] of the closed loop
        x_r->x, y_r->y (dashed: the same as x for a symmetric vehicle), z_r->z,
        psi_r->psi; 2 or 4 axes. Every phase is unwrapped (:func:`unwrapped_phase`): a closed
        loop's starts nearest 0 deg, a loop transfer's nearest -180 deg; grey lines mark
        -180 deg and every full turn from it.

    Examples
    --------
    >>> fig = bode(linearize("nlpd"), loops=True)
    >>> len(fig.axes), fig.axes[3].get_ylabel()
    (4, 'phase [deg]')
    """
    w = np.logspace(-2, math.log10(0.9 * math.pi / lin.dt), 800) if omega is None else np.asarray(omega, float)
    from matplotlib.figure import Figure
    from matplotlib.ticker import MultipleLocator

    fig = Figure(figsize=(12 if loops else 7, 6.5), layout="constrained")
    axes = fig.subplots(2, 2 if loops else 1, sharex="col", squeeze=False)
    marked = []
    step = _steps(progress, len(LOOPS))
    for (loop, (_, state)), color in zip(LOOPS.items(), ("C0", "C1", "C2", "C3")):
        style = {"color": color, "ls": "--" if loop == "y" else "-"}
        r = control.frequency_response(lin.sys[OUTPUTS.index(state), INPUTS.index(f"{state}_ref")], w).complex.ravel()
        axes[0, 0].semilogx(w, 20 * np.log10(np.abs(r)), label=f"{state}_r -> {state}", **style)
        axes[1, 0].semilogx(w, unwrapped_phase(r, 0.0), **style)
        if not loops:
            step()
            continue
        r = control.frequency_response(loop_transfer(lin, loop, at), w).complex.ravel()
        gain, phase = 20 * np.log10(np.abs(r)), unwrapped_phase(r, -180.0)
        m = loop_margins(lin, loop, at)
        axes[0, 1].semilogx(w, gain, label=f"L {loop}: {_margin_label(m)}", **style)
        axes[1, 1].semilogx(w, phase, **style)
        key = {k: round(m[k], 9) for k in ("phase_margin", "gain_crossover", "gain_increase", "gain_decrease")}
        if key in marked:                               # y's margins are x's: marked once
            step()
            continue
        marked.append(key)
        wgc = m["gain_crossover"]
        if math.isfinite(m["phase_margin"]) and math.isfinite(wgc):
            p = float(np.interp(np.log(wgc), np.log(w), phase))      # the phase at the crossover
            base = _nearest_minus_180(p - m["phase_margin"])
            axes[1, 1].plot([wgc, wgc], [base, base + m["phase_margin"]], color=color, lw=2.5,
                            solid_capstyle="butt", label=f"PM {loop}")
            axes[1, 1].plot([wgc], [base + m["phase_margin"]], "o", color=color, ms=5)
            axes[0, 1].plot([wgc], [0.0], "o", color=color, ms=5)
        for way in ("down", "up"):
            factor = m["gain_decrease" if way == "down" else "gain_increase"]
            wpc = m["gain_decrease_frequency" if way == "down" else "gain_increase_frequency"]
            if not (0.0 < factor < math.inf and math.isfinite(wpc)):
                continue
            g = -_db(factor)                            # the magnitude at the phase crossover
            axes[0, 1].plot([wpc, wpc], [0.0, g], color=color, lw=2.5, solid_capstyle="butt",
                            label=f"GM {way} {loop}")
            axes[0, 1].plot([wpc], [g], "s", color=color, ms=5)
            axes[1, 1].plot([wpc], [_nearest_minus_180(float(np.interp(np.log(wpc), np.log(w), phase)))], "s",
                            color=color, ms=5)
        step()
    axes[0, 0].set_ylim(bottom=max(axes[0, 0].get_ylim()[0], -150.0))
    for col, title in enumerate(["closed loop (discrete, dt = %g s)" % lin.dt, "loop transfers"][:axes.shape[1]]):
        axes[0, col].set(ylabel="magnitude [dB]", title=title)
        axes[1, col].set(ylabel="phase [deg]", xlabel="frequency [rad/s]")
        low, high = axes[1, col].get_ylim()
        axes[1, col].yaxis.set_major_locator(MultipleLocator(90.0 if high - low <= 720.0 else 180.0))
        axes[0, col].axhline(0.0, color="0.6", lw=0.6)
        for k in range(math.ceil((low + 180.0) / 360.0), math.floor((high + 180.0) / 360.0) + 1):
            axes[1, col].axhline(-180.0 + 360.0 * k, color="0.6", lw=0.6)
        axes[1, col].set_ylim(low, high)
        handles, labels = axes[0, col].get_legend_handles_labels()
        keep = [(h, lb) for h, lb in zip(handles, labels) if not lb.startswith(("PM ", "GM "))]
        axes[0, col].legend(*zip(*keep), fontsize=7 if col else 8, loc="upper right" if col else "lower left")
        for ax in axes[:, col]:
            ax.grid(True, which="both", alpha=0.3)
    fig.suptitle(f"{getattr(lin.controller, 'name', 'controller')}: linearised about hover")
    return fig


def report(controller="nlpd", lin: Linearization | None = None, *,
           progress: Callable[[int, int], None] | None = None, **kwargs) -> dict:
    """Poles, damping and margins of every loop beside the design's poles, as plain values.

    Parameters
    ----------
    controller : Controller or str
        The controller, if ``lin`` is not given.
    lin : Linearization, optional
        A linearisation to use as is (``controller`` and ``kwargs`` are then ignored).
    progress : callable, optional
        ``progress(done, total)`` at the start and after each of the four loops measured
        (its poles and its margins at the input and the output).
    **kwargs
        Keywords of :func:`linearize`.

    Returns
    -------
    dict
        ``controller`` (name), ``dt_s`` [s], ``stable``, ``spectral_radius``,
        ``hover_residual`` and ``loops``: per loop, ``poles`` [rad/s] as [re, im] (one of
        each pair, slowest first) with their ``natural_frequency`` [rad/s], ``damping`` and
        ``step_weight`` (:meth:`Linearization.loop_modes`, a complex pair's two weights
        added: a pair is one mode); the ``dominant`` pole, the mode of largest weight in the
        loop's step response, and the ``slowest`` (least decay rate), which need not be the
        same: a slow pole nearly cancelled by a zero weighs little; ``min_damping``;
        ``margins_input`` and ``margins_output`` (:func:`loop_margins`) and
        ``low_margins``, per break point the margins short of 30 deg or 6 dB
        (:func:`low_margins`); and where the controller has design gains for the loop
        (``position`` for x and y, ``altitude``, ``yaw``), their ``design_poles``, the
        ``nearest`` full-loop pole to each and its ``nearest_rel_distance``.

    Examples
    --------
    >>> r = report("nlpd")
    >>> x = r["loops"]["x"]
    >>> r["stable"], x["design_poles"], [round(v, 3) for v in x["dominant"]]
    (True, [-0.7, -4.3], [-0.658, 0.0])
    >>> [round(d, 2) for d in x["nearest_rel_distance"]]     # -0.7 survives, -4.3 does not
    [0.06, 0.85]
    """
    lin = lin or linearize(controller, **kwargs)
    controller = lin.controller
    out = {"controller": getattr(controller, "name", "controller"), "dt_s": lin.dt, "stable": lin.stable,
           "spectral_radius": float(np.max(np.abs(lin.poles()))), "hover_residual": lin.residual, "loops": {}}
    step = _steps(progress, len(LOOPS))
    for loop in LOOPS:
        p, weight = lin.loop_modes(loop)
        p, weight = p[p.imag >= 0], np.where(p.imag > 0, 2.0, 1.0)[p.imag >= 0] * weight[p.imag >= 0]
        wn = np.abs(p)
        with np.errstate(invalid="ignore"):
            zeta = np.where(np.isinf(wn), 1.0, -p.real / np.where(wn > 0, wn, 1.0))
        dom = p[np.argmax(weight)]
        margins = {at: loop_margins(lin, loop, at) for at in ("input", "output")}
        entry = out["loops"][loop] = {
            "poles": [[round(float(z.real), 6), round(float(z.imag), 6)] for z in p],
            "natural_frequency": wn.tolist(), "damping": zeta.tolist(), "step_weight": weight.tolist(),
            "dominant": [round(float(dom.real), 6), round(float(dom.imag), 6)],
            "slowest": [round(float(p[0].real), 6), round(float(p[0].imag), 6)], "min_damping": float(zeta.min()),
            "margins_input": margins["input"], "margins_output": margins["output"],
            "low_margins": {at: low_margins(m) for at, m in margins.items()}}
        design = getattr(getattr(controller, DESIGN[loop], None), "poles", None)
        if design is not None:
            d = np.atleast_1d(np.asarray(design, complex)).round(9)
            d = d[d.imag >= 0]                                   # one of each pair, as the poles
            near = [p[np.argmin(np.abs(p - z))] for z in d]
            entry["design_poles"] = [float(z.real) if z.imag == 0 else [float(z.real), float(z.imag)] for z in d]
            entry["nearest"] = [[float(q.real), float(q.imag)] for q in near]
            entry["nearest_rel_distance"] = [float(abs(q - z) / abs(z)) for q, z in zip(near, d)]
        step()
    return out


SUMMARY_NOTES = (
    ("dominant: the pole (a complex pair counted as one mode) with the largest weight in the loop's step "
     "response; slowest: the least decay rate."),
    ("GM down / up: how far the loop gain may fall / rise before the loop goes unstable [dB]; a loop with a GM "
     "down is conditionally stable (stable at its gain, unstable at a lower one, e.g. a PID's integral on a "
     "double integrator); none: no limit that way."),
    f"(!): below {MIN_PHASE_MARGIN_DEG:g} deg of phase margin or within {MIN_GAIN_MARGIN_DB:g} dB of 0 dB.",
)
"""The lines :func:`summary` ends with: what its rows mean."""


def summary(rep: dict) -> str:
    """:func:`report` as an aligned text table, one column per loop.

    Parameters
    ----------
    rep : dict
        What :func:`report` returns.

    Returns
    -------
    str
        A heading line (controller, dt, stable or not, and the loops whose margins are short),
        then one row per quantity: the dominant and slowest poles [rad/s], the least damping,
        how far the design poles moved, and the phase margins [deg] and gain margins [dB]
        at the input and the output, a short one marked (!); then :data:`SUMMARY_NOTES`.

    Examples
    --------
    >>> text = summary(report("nlpd"))
    >>> print(text.splitlines()[0])
    nlpd about hover, dt = 0.001 s: stable (every pole inside the unit circle), margins short on x, y, yaw (!)
    >>> print(text.splitlines()[4].split())
    ['min', 'damping', '0.363', '0.363', '0.884', '0.272']
    """
    def pole(p):
        return f"{p[0]:.3g}" if p[1] == 0 else f"{p[0]:.3g}±{p[1]:.3g}j"

    def design(e):
        return ", ".join(f"{z if isinstance(z, float) else complex(*z)}:{d:.0%}" for z, d in
                         zip(e.get("design_poles", []), e.get("nearest_rel_distance", []))) or "-"

    def pm(m):
        short = " (!)" if m["phase_margin"] < MIN_PHASE_MARGIN_DEG else ""
        return f"{m['phase_margin']:.1f}{short} @ {m['gain_crossover']:.3g}"

    def gm(m):
        down, up = m["gain_decrease_db"], m["gain_increase_db"]
        down = "none" if not math.isfinite(down) else f"{down:+.3g}" + (" (!)" if down > -MIN_GAIN_MARGIN_DB else "")
        up = "none" if not math.isfinite(up) else f"{up:+.3g}" + (" (!)" if up < MIN_GAIN_MARGIN_DB else "")
        return f"{down}, {up}"

    rows = [("dominant pole [rad/s]", lambda e: pole(e["dominant"])),
            ("slowest pole [rad/s]", lambda e: pole(e["slowest"])),
            ("min damping", lambda e: f"{e['min_damping']:.3f}"), ("design poles: nearest off by", design)]
    for at in ("input", "output"):
        rows += [(f"PM at the {at} [deg] @ [rad/s]", lambda e, m="margins_" + at: pm(e[m])),
                 (f"GM at the {at} [dB]: down, up", lambda e, m="margins_" + at: gm(e[m]))]
    table = [[""] + list(rep["loops"])] + [[name] + [cell(e) for e in rep["loops"].values()] for name, cell in rows]
    w = [max(len(row[j]) for row in table) + 2 for j in range(len(table[0]))]
    short = [loop for loop, e in rep["loops"].items() if any(e.get("low_margins", {}).values())]
    verdict = ("stable (every pole inside the unit circle)" if rep["stable"]
               else "UNSTABLE (a pole on or outside the unit circle)")
    head = f"{rep['controller']} about hover, dt = {rep['dt_s']:g} s: {verdict}"
    if short:
        head += f", margins short on {', '.join(short)} (!)"
    return "\n".join([head] + [r[0].ljust(w[0]) + "".join(c.rjust(k) for c, k in zip(r[1:], w[1:])) for r in table]
                     + [""] + [textwrap.fill(note, 100, subsequent_indent="  ") for note in SUMMARY_NOTES])


def to_json(rep: dict) -> str:
    """:func:`report` as strict JSON: an infinite or undefined number becomes null.

    Parameters
    ----------
    rep : dict
        What :func:`report` returns.

    Returns
    -------
    str
        The JSON text, indented.
    """
    from quadcruise.io.plainjson import dumps

    return dumps(rep, indent=2)


def write_analysis(lin: Linearization, rep: dict, out, *, force: bool = False,
                   progress: Callable[[int, int], None] | None = None):
    """An analysis's folder, written whole or not at all: ``analysis.json`` (:func:`to_json`),
    the Bode plots ``bode.png`` (at the plant input) and ``bode_output.png`` (at the
    measurement), and ``quadcruise.json`` (the controller, the control period, the version).

    Parameters
    ----------
    lin : Linearization
        The closed loop, from :func:`linearize`.
    rep : dict
        Its :func:`report`.
    out : str or path-like
        The folder; a non-empty one that quadcruise did not write is refused unless ``force``.
    force : bool
        Replace such a folder.
    progress : callable, optional
        ``progress(done, total)``: each Bode plot counts five steps, its four loops drawn
        (:func:`bode`) and its file saved.

    Returns
    -------
    pathlib.Path
        The folder written.
    """
    from pathlib import Path

    from quadcruise._version import __version__
    from quadcruise.io.files import MARKER, atomic_dir, check_output_dir
    from quadcruise.io.plainjson import dumps
    from quadcruise.plots.flight import save_figure

    out = check_output_dir(out, force)
    with atomic_dir(out) as tmp:
        tmp = Path(tmp)
        (tmp / "analysis.json").write_text(to_json(rep) + "\n")
        for k, (at, name) in enumerate((("input", "bode.png"), ("output", "bode_output.png"))):
            part = None if progress is None else (lambda done, _, k=k: progress(5 * k + done, 10))
            save_figure(bode(lin, loops=True, at=at, progress=part), tmp / name)
            if progress is not None:
                progress(5 * k + 5, 10)
        (tmp / MARKER).write_text(dumps({"workflow": "analyze", "controller": lin.controller,
                                         "dt_s": lin.dt, "version": __version__}) + "\n")
    return out


__all__ = ["HoverError", "Linearization", "linearize", "loop_transfer", "loop_margins", "low_margins", "bode",
           "unwrapped_phase", "report", "summary", "SUMMARY_NOTES", "MIN_PHASE_MARGIN_DEG", "MIN_GAIN_MARGIN_DB",
           "to_json", "write_analysis", "INPUTS", "OUTPUTS", "LOOPS"]
