"""Linear analysis of any closed loop about hover: :func:`linearize` and its result, a
:class:`Linearization` (poles, loops, margins; ``to_pandas``, ``summary``, ``plot``, ``write``).

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
velocity and attitude feedback closed: the outer loop's own margins
(:meth:`Linearization.loop_transfer`, :meth:`Linearization.margins`).

>>> lin = linearize("nlpd")
>>> lin.stable, sorted(lin.loops)
(True, ['x', 'y', 'yaw', 'z'])
>>> [round(float(p.real), 2) for p in lin.loop_poles("x") if p.imag == 0]
[-0.47, -0.66]
>>> round(lin.margins("z")["phase_margin"], 1)     # design.loop_margins: 65.1 (continuous)
65.0
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable

import control
import numpy as np
from scipy.sparse.csgraph import connected_components

from quadcruise import checks
from quadcruise import layout as L
from quadcruise.checks import describe
from quadcruise.errors import InputError
from quadcruise.model.actuators import mix
from quadcruise.model.vehicle import Vehicle
from quadcruise.workflows.linearization import INPUTS, LOOPS, OUTPUTS, Linearization, to_generalized


class HoverError(InputError):
    """The controller does not hold hover: there is no equilibrium to linearise about."""


def _period(x, u, vp, dt, n_sub):
    """One control period as the engine integrates it (:func:`quadcruise.sim.engine.rk4_step`,
    n_sub substeps, duties held) in still air with healthy rotors and the paper's
    kinematics (the exact ones agree to first order at hover): the next state."""
    from quadcruise.sim.engine import WORK_ROWS, rk4_step

    ext = np.zeros(L.EXT_SIZE)
    ext[L.EXT_E1 : L.EXT_E1 + 4] = 1.0
    x, u = np.array(x, dtype=float), np.ascontiguousarray(u, dtype=float)
    work = np.empty((WORK_ROWS, L.STATE_SIZE))
    for _ in range(n_sub):
        rk4_step(x, u, vp, ext, False, dt / n_sub, work, True)
    return x


def _jacobian(f, v0, eps):
    """Central differences of f at v0, step eps * max(1, |v_i|)."""
    steps = eps * np.maximum(1.0, np.abs(v0))
    return np.array(
        [(f(v0 + h * e) - f(v0 - h * e)) / (2.0 * h) for h, e in zip(steps, np.eye(v0.size), strict=False)]
    ).T


def _as_controller(controller):
    if isinstance(controller, str):
        from quadcruise.control import controller_from_name

        return controller_from_name(controller)
    if isinstance(controller, type):
        checks.fail("linearize()", "controller", controller, "a controller name or object")
    missing = [m for m in ("function", "gains", "memory") if not hasattr(controller, m)]
    if missing:
        raise InputError(
            f"controller must be a name or have .function, .gains() and .memory(); "
            f"{type(controller).__name__} lacks {', '.join(missing)}"
        )
    return controller


MIN_DT = 1e-9
"""The shortest control period :func:`linearize` takes [s]: at 1e-12 s the poles z = exp(s dt) are
within rounding of 1, and the s-plane poles computed from them are noise."""


def linearize(
    controller="nlpd",
    vehicle: Vehicle | None = None,
    *,
    dt: float = 1e-3,
    hover_z: float = 1.0,
    eps: float = 1e-6,
    max_step: float | None = None,
    memory=None,
    settle: int = 1,
    tol: float = 1e-6,
    progress: Callable[[int, int], None] | None = None,
) -> Linearization:
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
    w = "linearize()"  # every argument checked before any work
    controller = _as_controller(controller)  # (its function may be plain Python: it is called here)
    from quadcruise.control.px4 import Px4

    if isinstance(controller, Px4):  # its loops run at their own rates, which one period at t = 0 misses
        raise InputError(
            "linearize differentiates one period of a single-rate loop; the px4 controller runs its loops at "
            "their own rates: use quadcruise.workflows.px4margins.px4_margins (analyze --controller px4)"
        )
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
        raise InputError(f"dt must be a positive number of seconds, got {describe(dt)}")
    if dt < MIN_DT:
        raise InputError(
            f"dt = {dt:g} s is below {MIN_DT:g} s: the discrete poles would lie within rounding of 1 "
            "and read as unstable; linearise at a real control period"
        )
    vp = np.ascontiguousarray(vehicle.rows()[0])
    gains = np.ascontiguousarray(controller.gains(), dtype=float)
    mem0 = np.array(controller.memory() if memory is None else memory, dtype=float).ravel()
    n, C = L.STATE_SIZE + mem0.size, mem0.size
    n_sub = max(1, math.ceil(dt / (max_step or dt) - 1e-9))
    x0, ref0 = np.zeros(L.STATE_SIZE), np.zeros(len(L.REF_NAMES))
    x0[L.Z], x0[L.F1 : L.F1 + 4], ref0[L.REF_Z] = hover_z, vp[L.P_M] * vp[L.P_G] / 4.0, hover_z
    cols = [L.REF_NAMES.index(name) for name in INPUTS]
    step = _steps(progress, 3)

    def ctrl(v):  # (x, memory, set-points) -> (duties, next memory, flags)
        ref, mem, cmd = ref0.copy(), v[L.STATE_SIZE : n].copy(), np.zeros(L.CMD_SIZE)
        ref[cols] = v[n:]
        controller.function(0.0, dt, np.ascontiguousarray(v[: L.STATE_SIZE]), ref, vp, gains, mem, cmd)
        return np.concatenate([cmd[:4], mem, cmd[L.CMD_FLAGS : L.CMD_FLAGS + 1]])

    for _ in range(settle):
        mem0 = ctrl(np.concatenate([x0, mem0, ref0[cols]]))[4 : 4 + C]
    v0 = np.concatenate([x0, mem0, ref0[cols]])
    out0 = ctrl(v0)
    u0 = out0[:4]
    drift = np.concatenate([_period(x0, np.clip(u0, 0.0, 1.0), vp, dt, n_sub) - x0, out0[4 : 4 + C] - mem0]) / dt
    names = list(L.STATE_NAMES) + [f"mem{i}" for i in range(C)]
    if not np.all(np.abs(drift) <= tol):
        i = int(np.argmax(np.where(np.isfinite(drift), np.abs(drift), np.inf)))
        who = getattr(controller, "name", "the controller")
        raise HoverError(
            f"{who} does not hold hover at z = {hover_z:g} m: '{names[i]}' moves at {drift[i]:.3g} "
            f"per second (tolerance {tol:g}), so there is no equilibrium to linearise about"
        )
    if np.any(u0 <= 0.0) or np.any(u0 >= 1.0):
        raise HoverError(
            f"a hover duty sits on its clip to [0, 1] ({np.round(u0, 4).tolist()}): "
            f"the loop is not differentiable there"
        )
    if out0[-1] != 0.0:
        warnings.warn(f"the controller flags a limit at hover (flags {out0[-1]:g})", stacklevel=2)
    step()

    # the period map's Jacobian by the chain rule: controller, then plant (a duty clip is inactive)
    G = _jacobian(lambda v: ctrl(v)[: 4 + C], v0, eps)
    step()
    P = _jacobian(lambda v: _period(v[: L.STATE_SIZE], v[L.STATE_SIZE :], vp, dt, n_sub), np.r_[x0, u0], eps)
    step()
    Ap, Bp = P[:, : L.STATE_SIZE], P[:, L.STATE_SIZE :]
    (Kx, Km, Kr), (Hx, Hm, Hr) = np.split(G[:4], [L.STATE_SIZE, n], axis=1), np.split(G[4:], [L.STATE_SIZE, n], axis=1)
    A = np.block([[Ap + Bp @ Kx, Bp @ Km], [Hx, Hm]])
    Cy = np.eye(n)[[L.STATE_NAMES.index(name) for name in OUTPUTS]]
    sys = control.ss(A, np.vstack([Bp @ Kr, Hr]), Cy, 0.0, dt, inputs=INPUTS, outputs=OUTPUTS, states=names)
    mixer = vp[L.P_K] * np.array([mix(*row, vp[L.P_D]) for row in np.eye(4)]).T
    return Linearization(
        sys,
        float(dt),
        controller,
        Ap,
        Bp,
        Kx,
        Km,
        Hx,
        Hm,
        mixer,
        _loops(A, mixer),
        float(np.max(np.abs(drift))),
        vehicle,
    )


def _loops(A, mixer):
    """Each loop's state indices: the connected component of A (in U1..U4 coordinates, where
    the loops decouple at hover) that holds the loop's measured output."""
    S = to_generalized(A.shape[0], mixer)
    At = np.abs(S @ A @ np.linalg.inv(S) - np.eye(A.shape[0]))
    _, label = connected_components(At > 1e-9 * At.max(), directed=False)
    return {loop: np.flatnonzero(label == label[L.STATE_NAMES.index(state)]) for loop, (_, state) in LOOPS.items()}


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


__all__ = ["INPUTS", "LOOPS", "MIN_DT", "OUTPUTS", "HoverError", "Linearization", "linearize"]
