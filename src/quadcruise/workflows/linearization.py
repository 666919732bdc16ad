"""The result of :func:`quadcruise.workflows.analysis.linearize`: the discrete closed loop about
hover, :class:`Linearization` (poles, loops, margins; ``to_pandas``, ``summary``, ``plot``,
``write``), and the names of its inputs, outputs and loops. Where the loops are broken for
margins: :mod:`quadcruise.workflows.analysis`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import control
import numpy as np
import scipy.linalg

from quadcruise.errors import InputError
from quadcruise.layout import F1, STATE_NAMES, STATE_SIZE
from quadcruise.metrics import margins as margin_metrics
from quadcruise.metrics.summary import Summary
from quadcruise.workflows.loop_summary import summary_data, summary_text

INPUTS = ("x_ref", "y_ref", "z_ref", "psi_ref")
OUTPUTS = ("x", "y", "z", "phi", "theta", "psi")
LOOPS = {"x": (2, "x"), "y": (1, "y"), "z": (0, "z"), "yaw": (3, "psi")}
"""Each loop's generalized input (0..3: U1..U4) and measured output (a state name)."""


def to_generalized(n: int, mixer: np.ndarray) -> np.ndarray:
    """The change of state that replaces the rotor thrusts F1..F4 by U1..U4 (up to scale)."""
    S = np.eye(n)
    S[F1 : F1 + 4, F1 : F1 + 4] = mixer / mixer[0, 0]
    return S


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
    vehicle : Vehicle, optional
        The vehicle linearised (recorded in the folder's ``quadcruise.json``).
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
    vehicle: object = None

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
        S = to_generalized(self.sys.nstates, self.mixer)
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
        >>> from quadcruise.workflows.analysis import linearize
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
        >>> from quadcruise.workflows.analysis import linearize
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
        >>> from quadcruise.workflows.analysis import linearize
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
                dumps(
                    {
                        "workflow": "analyze",
                        "controller": self.controller,
                        "vehicle": None if self.vehicle is None else self.vehicle.to_dict(),
                        "dt_s": self.dt,
                        "version": __version__,
                    }
                )
                + "\n"
            )
        return out


def _check_loop(loop: str) -> str:
    if loop not in LOOPS:
        raise InputError(f"unknown loop {loop!r}; choose one of {', '.join(LOOPS)}")
    return loop


__all__ = ["INPUTS", "LOOPS", "OUTPUTS", "Linearization", "to_generalized"]
