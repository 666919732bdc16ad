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
from dataclasses import dataclass
from pathlib import Path

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
from quadcruise.metrics import margins as margin_metrics
from quadcruise.metrics.summary import Summary
from quadcruise.model.actuators import mix
from quadcruise.model.vehicle import Vehicle
from quadcruise.workflows.loop_summary import summary_data, summary_text

INPUTS = ("x_ref", "y_ref", "z_ref", "psi_ref")
OUTPUTS = ("x", "y", "z", "phi", "theta", "psi")
LOOPS = {"x": (2, "x"), "y": (1, "y"), "z": (0, "z"), "yaw": (3, "psi")}
"""Each loop's generalized input (0..3: U1..U4) and measured output (a state name)."""


class HoverError(InputError):
    """The controller does not hold hover: there is no equilibrium to linearise about."""


def _period(x, u, vp, dt, n_sub):
    """One control period as the engine integrates it (:func:`quadcruise.sim.engine.rk4_step`,
    n_sub substeps, duties held) in still air with healthy rotors and the paper's
    kinematics (the exact ones agree to first order at hover): the next state."""
    from quadcruise.sim.engine import WORK_ROWS, rk4_step

    ext = np.zeros(EXT_SIZE)
    ext[EXT_E1 : EXT_E1 + 4] = 1.0
    x, u = np.array(x, dtype=float), np.ascontiguousarray(u, dtype=float)
    work = np.empty((WORK_ROWS, STATE_SIZE))
    for _ in range(n_sub):
        rk4_step(x, u, vp, ext, False, dt / n_sub, work, True)
    return x


def _jacobian(f, v0, eps):
    """Central differences of f at v0, step eps * max(1, |v_i|)."""
    steps = eps * np.maximum(1.0, np.abs(v0))
    return np.array(
        [(f(v0 + h * e) - f(v0 - h * e)) / (2.0 * h) for h, e in zip(steps, np.eye(v0.size), strict=False)]
    ).T


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
    A result like the others (:class:`quadcruise.protocols.ResultLike`): :meth:`to_pandas`
    (the loops' modes and margins), :meth:`summary`, :meth:`plot` (Bode) and :meth:`write`.

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
        with np.errstate(divide="ignore", invalid="ignore"):  # inf for a marginal mode
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
            raise InputError(
                "the loop has purely discrete modes (poles at z = 0 or on the negative real "
                "axis, e.g. a one-period memory): it has no continuous equivalent"
            )
        L = scipy.linalg.logm(np.block([[self.sys.A, self.sys.B], [np.zeros((m, n)), np.eye(m)]])).real / self.dt
        return control.ss(
            L[:n, :n],
            L[:n, n:],
            self.sys.C,
            self.sys.D,
            inputs=INPUTS,
            outputs=OUTPUTS,
            states=list(self.sys.state_labels),
        )

    def closed_loop(self, loop: str) -> control.StateSpace:
        """One loop's closed loop, from its set-point to its output (``x_ref`` to ``x``, ...).

        Parameters
        ----------
        loop : str
            ``"x"``, ``"y"``, ``"z"`` or ``"yaw"``.

        Returns
        -------
        control.StateSpace
            One input and one output of ``sys``, labelled, sampling time ``dt``.
        """
        state = LOOPS[_check_loop(loop)][1]
        return self.sys[OUTPUTS.index(state), INPUTS.index(f"{state}_ref")]

    def loop_transfer(self, loop: str = "x", at: str = "input") -> control.StateSpace:
        """The discrete loop transfer L(z) of one loop broken at the plant input or output.

        Parameters
        ----------
        loop : str
            ``"x"``, ``"y"``, ``"z"`` or ``"yaw"``; the others stay closed.
        at : str
            ``"input"``: at the loop's generalized input U1..U4; ``"output"``: at the position
            (or yaw) measurement the controller sees (see the module).

        Returns
        -------
        control.StateSpace
            L(z), one input and one output, sampling time ``dt``, signed for negative
            feedback (the closed loop is L / (1 + L)).
        """
        u_idx, state = LOOPS[_check_loop(loop)]
        Ap, Bp, Kx, Km, Hx, Hm = self.plant_A, self.plant_B, self.K_state, self.K_memory, self.H_state, self.H_memory
        C = Hm.shape[0]
        if at == "input":  # w replaces the controller's U_j at the plant input
            Bu, KU, KmU = Bp @ np.linalg.inv(self.mixer), self.mixer @ Kx, self.mixer @ Km
            e = np.eye(4)[:, [u_idx]]
            keep = np.eye(4) - e @ e.T
            A = np.block([[Ap + Bu @ keep @ KU, Bu @ keep @ KmU], [Hx, Hm]])
            B, Cl = np.vstack([Bu @ e, np.zeros((C, 1))]), -np.hstack([KU[u_idx], KmU[u_idx]])[None, :]
        elif at == "output":  # w replaces the measured output the controller sees
            e = np.eye(STATE_SIZE)[:, [STATE_NAMES.index(state)]]
            keep = np.eye(STATE_SIZE) - e @ e.T
            A = np.block([[Ap + Bp @ Kx @ keep, Bp @ Km], [Hx @ keep, Hm]])
            B, Cl = np.vstack([Bp @ Kx @ e, Hx @ e]), -np.hstack([e.T, np.zeros((1, C))])
        else:
            raise InputError(f"at must be 'input' or 'output', got {at!r}")
        return control.ss(A, B, Cl, 0.0, self.dt)

    def margins(self, loop: str = "x", at: str = "input") -> dict:
        """The margins of one loop broken at ``at`` (:meth:`loop_transfer`).

        Parameters
        ----------
        loop : str
            ``"x"``, ``"y"``, ``"z"`` or ``"yaw"``.
        at : str
            Where the loop is broken: ``"input"`` or ``"output"``.

        Returns
        -------
        dict
            :func:`quadcruise.metrics.margins.margins`: phase margin [deg], gain margins down
            and up [-] and [dB], each at its frequency [rad/s].

        Examples
        --------
        >>> m = linearize("nlpd").margins("yaw")          # design.loop_margins: 24.5 deg
        >>> round(m["phase_margin"], 1), round(m["gain_crossover"], 1)
        (24.1, 12.5)
        """
        return margin_metrics.margins(self.loop_transfer(loop, at))

    # --- ResultLike ----------------------------------------------------------------------
    def to_pandas(self):
        """The loops' modes and margins: one row per loop and mode (a complex pair is one mode).

        Returns
        -------
        pandas.DataFrame
            ``loop``, the mode's pole ``real`` and ``imag`` [rad/s] (Im >= 0, slowest first),
            ``natural_frequency`` [rad/s], ``damping``, ``step_weight``, whether it is the
            loop's ``dominant`` and ``slowest`` mode (:meth:`summary`), and the loop's margins
            at the plant ``input`` and the ``output``: ``{at}_phase_margin_deg``,
            ``{at}_gain_crossover_rad_s``, ``{at}_gain_decrease_db``, ``{at}_gain_increase_db``
            (repeated on each of its modes).
        """
        import pandas as pd

        rows = []
        for loop, e in self.summary()["loops"].items():
            at_cols = {}
            for at in ("input", "output"):
                m = e["margins_" + at]
                at_cols.update(
                    {
                        f"{at}_phase_margin_deg": m["phase_margin"],
                        f"{at}_gain_crossover_rad_s": m["gain_crossover"],
                        f"{at}_gain_decrease_db": m["gain_decrease_db"],
                        f"{at}_gain_increase_db": m["gain_increase_db"],
                    }
                )
            for p, wn, zeta, weight in zip(
                e["poles"], e["natural_frequency"], e["damping"], e["step_weight"], strict=False
            ):
                rows.append(
                    {
                        "loop": loop,
                        "real": p[0],
                        "imag": p[1],
                        "natural_frequency": wn,
                        "damping": zeta,
                        "step_weight": weight,
                        "dominant": p == e["dominant"],
                        "slowest": p == e["slowest"],
                        **at_cols,
                    }
                )
        return pd.DataFrame(rows)

    def summary(self, progress: Callable[[int, int], None] | None = None) -> Summary:
        """Poles, damping and margins of every loop beside the design's poles.

        Parameters
        ----------
        progress : callable, optional
            ``progress(done, total)`` at the start and after each of the four loops measured.

        Returns
        -------
        Summary
            The keys of :func:`quadcruise.workflows.loop_summary.summary_data` (``stable``,
            ``loops``: per loop its poles, ``dominant``, ``slowest``, ``min_damping``,
            ``margins_input``, ``margins_output``, ``low_margins``, design poles); prints as
            :func:`quadcruise.workflows.loop_summary.summary_text`.

        Examples
        --------
        >>> s = linearize("nlpd").summary()
        >>> x = s["loops"]["x"]
        >>> s["stable"], x["design_poles"], [round(v, 3) for v in x["dominant"]]
        (True, [-0.7, -4.3], [-0.658, 0.0])
        >>> [round(d, 2) for d in x["nearest_rel_distance"]]     # -0.7 survives, -4.3 does not
        [0.06, 0.85]
        >>> print(str(s).splitlines()[0])
        nlpd about hover, dt = 0.001 s: stable (every pole inside the unit circle), margins short on x, y, yaw (!)
        >>> print(str(s).splitlines()[4].split())
        ['min', 'damping', '0.363', '0.363', '0.884', '0.272']
        """
        data = summary_data(self, progress)
        return Summary(data, summary_text(data))

    def plot(
        self, *, loops: bool = True, at: str = "input", omega=None, progress: Callable[[int, int], None] | None = None
    ):
        """Bode plots: the closed loops and the loop transfers with their margins marked.

        Parameters
        ----------
        loops : bool
            Draw the loop transfers beside the closed loops.
        at : str
            Where the loops are broken: ``"input"`` or ``"output"``.
        omega : array_like, optional
            Frequencies [rad/s]; see :func:`quadcruise.plots.bode.plot_bode`.
        progress : callable, optional
            ``progress(done, total)`` at the start and after each of the four loops drawn.

        Returns
        -------
        matplotlib.figure.Figure
            :func:`quadcruise.plots.bode.plot_bode`.

        Examples
        --------
        >>> fig = linearize("nlpd").plot()
        >>> len(fig.axes), fig.axes[3].get_ylabel()
        (4, 'phase [deg]')
        """
        from quadcruise.plots.bode import plot_bode

        if at not in ("input", "output"):
            raise InputError(f"at must be 'input' or 'output', got {at!r}")
        return plot_bode(self, loops=loops, omega=omega, at=at, progress=progress)

    def write(self, out, *, force: bool = False, progress: Callable[[int, int], None] | None = None) -> Path:
        """The analysis's folder, written whole or not at all: ``analysis.json`` (:meth:`summary`
        as strict JSON: an infinite or undefined number becomes null), the Bode plots
        ``bode.png`` (at the plant input) and ``bode_output.png`` (at the measurement), and
        ``quadcruise.json`` (the controller, the control period, the version).

        Parameters
        ----------
        out : str or path-like
            The folder; a non-empty one that quadcruise did not write is refused unless ``force``.
        force : bool
            Replace such a folder.
        progress : callable, optional
            ``progress(done, total)``: each Bode plot counts five steps, its four loops drawn
            and its file saved.

        Returns
        -------
        pathlib.Path
            The folder written.
        """
        from quadcruise._version import __version__
        from quadcruise.io.files import MARKER, atomic_dir, check_output_dir
        from quadcruise.io.plainjson import dumps
        from quadcruise.plots.flight import save_figure

        out = check_output_dir(out, force)
        data = self.summary().to_dict()
        with atomic_dir(out) as tmp:
            tmp = Path(tmp)
            (tmp / "analysis.json").write_text(dumps(data, indent=2) + "\n")
            for k, (at, name) in enumerate((("input", "bode.png"), ("output", "bode_output.png"))):
                part = None if progress is None else (lambda done, _, k=k: progress(5 * k + done, 10))
                save_figure(self.plot(at=at, progress=part), tmp / name)
                if progress is not None:
                    progress(5 * k + 5, 10)
            (tmp / MARKER).write_text(
                dumps({"workflow": "analyze", "controller": self.controller, "dt_s": self.dt, "version": __version__})
                + "\n"
            )
        return out


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
        raise InputError(
            f"dt = {dt:g} s is below {MIN_DT:g} s: the discrete poles would lie within rounding of 1 "
            "and read as unstable; linearise at a real control period"
        )
    vp = np.ascontiguousarray(vehicle.rows()[0])
    gains = np.ascontiguousarray(controller.gains(), dtype=float)
    mem0 = np.array(controller.memory() if memory is None else memory, dtype=float).ravel()
    n, C = STATE_SIZE + mem0.size, mem0.size
    n_sub = max(1, math.ceil(dt / (max_step or dt) - 1e-9))
    x0, ref0 = np.zeros(STATE_SIZE), np.zeros(len(REF_NAMES))
    x0[Z], x0[F1 : F1 + 4], ref0[REF_Z] = hover_z, vp[P_M] * vp[P_G] / 4.0, hover_z
    cols = [REF_NAMES.index(name) for name in INPUTS]
    step = _steps(progress, 3)

    def ctrl(v):  # (x, memory, set-points) -> (duties, next memory, flags)
        ref, mem, cmd = ref0.copy(), v[STATE_SIZE:n].copy(), np.zeros(CMD_SIZE)
        ref[cols] = v[n:]
        controller.function(0.0, dt, np.ascontiguousarray(v[:STATE_SIZE]), ref, vp, gains, mem, cmd)
        return np.concatenate([cmd[:4], mem, cmd[CMD_FLAGS : CMD_FLAGS + 1]])

    for _ in range(settle):
        mem0 = ctrl(np.concatenate([x0, mem0, ref0[cols]]))[4 : 4 + C]
    v0 = np.concatenate([x0, mem0, ref0[cols]])
    out0 = ctrl(v0)
    u0 = out0[:4]
    drift = np.concatenate([_period(x0, np.clip(u0, 0.0, 1.0), vp, dt, n_sub) - x0, out0[4 : 4 + C] - mem0]) / dt
    names = list(STATE_NAMES) + [f"mem{i}" for i in range(C)]
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
    P = _jacobian(lambda v: _period(v[:STATE_SIZE], v[STATE_SIZE:], vp, dt, n_sub), np.r_[x0, u0], eps)
    step()
    Ap, Bp = P[:, :STATE_SIZE], P[:, STATE_SIZE:]
    (Kx, Km, Kr), (Hx, Hm, Hr) = np.split(G[:4], [STATE_SIZE, n], axis=1), np.split(G[4:], [STATE_SIZE, n], axis=1)
    A = np.block([[Ap + Bp @ Kx, Bp @ Km], [Hx, Hm]])
    Cy = np.eye(n)[[STATE_NAMES.index(name) for name in OUTPUTS]]
    sys = control.ss(A, np.vstack([Bp @ Kr, Hr]), Cy, 0.0, dt, inputs=INPUTS, outputs=OUTPUTS, states=names)
    mixer = vp[P_K] * np.array([mix(*row, vp[P_D]) for row in np.eye(4)]).T
    return Linearization(
        sys, float(dt), controller, Ap, Bp, Kx, Km, Hx, Hm, mixer, _loops(A, mixer), float(np.max(np.abs(drift)))
    )


def _to_generalized(n, mixer):
    """The change of state that replaces the rotor thrusts F1..F4 by U1..U4 (up to scale)."""
    S = np.eye(n)
    S[F1 : F1 + 4, F1 : F1 + 4] = mixer / mixer[0, 0]
    return S


def _loops(A, mixer):
    """Each loop's state indices: the connected component of A (in U1..U4 coordinates, where
    the loops decouple at hover) that holds the loop's measured output."""
    S = _to_generalized(A.shape[0], mixer)
    At = np.abs(S @ A @ np.linalg.inv(S) - np.eye(A.shape[0]))
    _, label = connected_components(At > 1e-9 * At.max(), directed=False)
    return {loop: np.flatnonzero(label == label[STATE_NAMES.index(state)]) for loop, (_, state) in LOOPS.items()}


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
