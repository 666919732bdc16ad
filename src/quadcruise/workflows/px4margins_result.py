"""The result of :func:`quadcruise.workflows.px4margins.px4_margins`: :class:`Px4Margins` (each
loop's margins, crossover, bandwidth and PX4's targets; ``to_pandas``, ``summary``, ``plot``,
``write``) and the targets with their sources, :data:`TARGETS`."""

from __future__ import annotations

import math
import textwrap
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import control
import numpy as np

from quadcruise.metrics import margins as margin_metrics
from quadcruise.metrics.summary import Summary

__all__ = ["AXES", "LOOP_ORDER", "TARGETS", "LoopModel", "Px4Margins", "bandwidth", "rise_time"]

LOOP_ORDER = ("rate", "attitude", "velocity", "position")
AXES = {"rate": ("roll", "pitch", "yaw"), "attitude": ("roll", "pitch", "yaw")} | {
    k: ("x", "y", "z") for k in ("velocity", "position")
}
"""Each loop's axes: PX4's body axes (FRD roll, pitch, yaw) for the rate and attitude loops;
quadcruise's world axes (x through the pitch, y through the roll, z the thrust) for the others."""

_RISE_SOURCE = (
    "PX4 v1.15 autotune: MC_AT_RISE_TIME default 0.14 s for roll and pitch, 0.2 s for yaw "
    "(src/modules/mc_autotune_attitude_control/mc_autotune_attitude_control.cpp, _params.c)"
)
TARGETS = {
    "phase_margin_deg": (
        margin_metrics.MIN_PHASE_MARGIN_DEG,
        "classical floor (quadcruise.metrics.margins); PX4 v1.15's tuning guide and autotune state no margin",
    ),
    "gain_margin_db": (
        margin_metrics.MIN_GAIN_MARGIN_DB,
        "classical floor, each way (quadcruise.metrics.margins); PX4 v1.15 states none",
    ),
    "rate_rise_time_s": ({"roll": 0.14, "pitch": 0.14, "yaw": 0.2}, _RISE_SOURCE),
}
"""Each target's value and where it comes from."""


@dataclass(frozen=True)
class LoopModel:
    """One loop and axis: its loop transfer broken at the controller's output and its closed loop.

    Parameters
    ----------
    L : control.StateSpace
        The loop transfer (negative feedback: the closed loop is L / (1 + L)), sampling time ``period``.
    T : control.StateSpace
        The closed loop from the setpoint to the loop's output.
    period : float
        The loop's period [s].
    broken_at : str
        Where the loop is broken (the controller's output, and its unit).
    output : str
        The closed loop's output unit.
    """

    L: control.StateSpace
    T: control.StateSpace
    period: float
    broken_at: str
    output: str


def _grid(period, n=3000):
    return np.logspace(-2, math.log10(0.999 * math.pi / period), n)


def bandwidth(T: control.StateSpace) -> float:
    """The closed loop's -3 dB bandwidth: the first frequency where ``|T|`` falls below ``|T(0)| / sqrt 2``.

    Parameters
    ----------
    T : control.StateSpace
        A discrete closed loop, one input, one output.

    Returns
    -------
    float
        [rad/s]; nan if it stays above within the Nyquist frequency.

    Examples
    --------
    >>> T = control.c2d(control.tf([10.0], [1.0, 10.0]), 0.001)   # a 10 rad/s lag
    >>> round(bandwidth(T), 1)
    10.0
    """
    w = _grid(T.dt)
    mag = np.abs(control.frequency_response(T, w).complex.ravel())
    dc = abs(complex(np.asarray(control.frequency_response(T, [1e-4]).complex).ravel()[0]))
    below = np.flatnonzero(mag < dc / math.sqrt(2.0))
    if below.size == 0:
        return math.nan
    k = int(below[0])
    if k == 0:
        return float(w[0])
    # interpolate in log-frequency between the last point above and the first below
    lo, hi = mag[k - 1], mag[k]
    f = (lo - dc / math.sqrt(2.0)) / (lo - hi)
    return float(math.exp(math.log(w[k - 1]) + f * (math.log(w[k]) - math.log(w[k - 1]))))


def rise_time(T: control.StateSpace, horizon: float = 5.0) -> float:
    """10-90 % rise time of the closed loop's step response [s] (nan if it never reaches 90 %).

    Parameters
    ----------
    T : control.StateSpace
        A discrete closed loop, one input, one output.
    horizon : float
        How long the step is simulated [s].

    Returns
    -------
    float

    Examples
    --------
    >>> T = control.c2d(control.tf([10.0], [1.0, 10.0]), 0.001)
    >>> round(rise_time(T), 3)                    # ln 9 / 10
    0.22
    """
    T = control.ss(T)
    n = int(round(horizon / T.dt))
    A, B, C, D = np.asarray(T.A), np.asarray(T.B).ravel(), np.asarray(T.C).ravel(), float(np.asarray(T.D).ravel()[0])
    x, y = np.zeros(A.shape[0]), np.empty(n)
    for k in range(n):
        y[k] = C @ x + D
        x = A @ x + B
    final = y[-1]
    if not np.isfinite(final) or final == 0.0:
        return math.nan
    t = np.arange(n) * T.dt
    y = y / final
    a, b = np.flatnonzero(y >= 0.1), np.flatnonzero(y >= 0.9)
    return math.nan if b.size == 0 else float(t[b[0]] - t[a[0]])


def _judge(loop, axis, m, bw, rise, stable):
    pm_t, gm_t = TARGETS["phase_margin_deg"][0], TARGETS["gain_margin_db"][0]
    short = margin_metrics.low_margins(m)
    entry = {
        "crossover_rad_s": m["gain_crossover"],
        "phase_margin_deg": m["phase_margin"],
        "gain_margin_up_db": m["gain_increase_db"],
        "gain_margin_down_db": m["gain_decrease_db"],
        "phase_crossover_rad_s": m["gain_increase_frequency"],
        "bandwidth_rad_s": bw,
        "bandwidth_hz": bw / (2.0 * math.pi),
        "stable": stable,
        "meets_margins": bool(not short and stable),
        "short": short,
    }
    if loop == "rate":
        target = TARGETS["rate_rise_time_s"][0][axis]
        entry.update(rise_time_s=rise, rise_time_target_s=target, meets_rise_time=bool(rise <= target))
    entry["targets"] = {"phase_margin_deg": pm_t, "gain_margin_db": gm_t}
    return entry


@dataclass(frozen=True)
class Px4Margins:
    """The px4 controller's loops about hover (:func:`~quadcruise.workflows.px4margins.px4_margins`).

    Parameters
    ----------
    loops : dict
        ``(loop, axis)`` -> :class:`LoopModel`; loops ``rate``, ``attitude``, ``velocity``,
        ``position`` (:data:`AXES`).
    controller : Px4
        The controller analysed.
    vehicle : Vehicle
        The paper vehicle linearised (a rotor vehicle's equivalent).
    setup : dict
        The loops' periods [s], the torque per unit normalised torque [N m], the vertical
        acceleration per setpoint, the hover command, the motor bandwidth, the inertia.
    """

    loops: dict
    controller: object
    vehicle: object
    setup: dict

    def margins(self, loop: str, axis: str) -> dict:
        """One loop's margins (:func:`quadcruise.metrics.margins.margins` of its loop transfer).

        Parameters
        ----------
        loop : str
            ``rate``, ``attitude``, ``velocity`` or ``position``.
        axis : str
            One of :data:`AXES` [loop].

        Returns
        -------
        dict
        """
        return margin_metrics.margins(self._model(loop, axis).L)

    def _model(self, loop, axis):
        from quadcruise.errors import InputError

        if (loop, axis) not in self.loops:
            raise InputError(f"no px4 loop {loop!r} axis {axis!r}; loops: {', '.join(LOOP_ORDER)}, axes: {AXES}")
        return self.loops[(loop, axis)]

    def summary(self) -> Summary:
        """Per loop and axis: crossover [rad/s], phase margin [deg], gain margins up and down
        [dB], closed-loop bandwidth [rad/s, Hz], the rate loops' rise time, and whether each
        meets :data:`TARGETS` (with their sources).

        Returns
        -------
        Summary
            ``controller``, ``setup``, ``targets`` (value and source), ``loops`` [loop][axis],
            ``meets`` (every loop's margins); prints as a table.
        """
        out = {"controller": "px4", "params_source": getattr(self.controller.params, "source", None)}
        out["setup"] = dict(self.setup)
        out["targets"] = {k: {"value": v, "source": s} for k, (v, s) in TARGETS.items()}
        loops: dict = {}
        for (loop, axis), model in self.loops.items():
            m = margin_metrics.margins(model.L)
            loops.setdefault(loop, {})[axis] = _judge(
                loop,
                axis,
                m,
                bandwidth(model.T),
                rise_time(model.T) if loop == "rate" else math.nan,
                _stable(model.T),
            ) | {"period_s": model.period, "broken_at": model.broken_at}
        out["loops"] = {k: loops[k] for k in LOOP_ORDER if k in loops}
        out["meets_margins"] = all(e["meets_margins"] for v in loops.values() for e in v.values())
        return Summary(out, _text(out))

    def to_pandas(self):
        """One row per loop and axis: the :meth:`summary` figures.

        Returns
        -------
        pandas.DataFrame
        """
        import pandas as pd

        rows = []
        for loop, axes in self.summary()["loops"].items():
            for axis, e in axes.items():
                rows.append(
                    {"loop": loop, "axis": axis, **{k: v for k, v in e.items() if k not in ("targets", "short")}}
                )
        return pd.DataFrame(rows)

    def plot(self, progress: Callable[[int, int], None] | None = None):
        """Bode plots of the loop transfers, one column per loop, crossovers marked.

        Parameters
        ----------
        progress : callable, optional
            ``progress(done, total)`` after each loop drawn.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from matplotlib.figure import Figure

        fig = Figure(figsize=(16, 7), layout="constrained")
        axs = fig.subplots(2, len(LOOP_ORDER), sharex="col")
        for j, loop in enumerate(LOOP_ORDER):
            for axis in AXES[loop]:
                model = self.loops[(loop, axis)]
                w = _grid(model.period, 800)
                r = control.frequency_response(model.L, w).complex.ravel()
                (line,) = axs[0, j].semilogx(w, 20 * np.log10(np.abs(r)), label=axis)
                axs[1, j].semilogx(w, _phase(r), color=line.get_color())
                m = margin_metrics.margins(model.L)
                if math.isfinite(m["gain_crossover"]):
                    axs[0, j].axvline(m["gain_crossover"], color=line.get_color(), ls=":", lw=0.8)
            axs[0, j].axhline(0.0, color="k", lw=0.6)
            axs[1, j].axhline(-180.0, color="k", lw=0.6)
            axs[0, j].set_title(f"{loop} loop (broken at {self.loops[(loop, AXES[loop][0])].broken_at})", fontsize=9)
            axs[0, j].legend(fontsize=8)
            axs[1, j].set_xlabel("frequency [rad/s]")
            if progress is not None:
                progress(j + 1, len(LOOP_ORDER))
        axs[0, 0].set_ylabel("|L| [dB]")
        axs[1, 0].set_ylabel("phase of L [deg]")
        return fig

    def write(self, out, *, force: bool = False, progress: Callable[[int, int], None] | None = None) -> Path:
        """The folder, whole or not at all: ``analysis.json`` (:meth:`summary`, strict JSON),
        ``bode.png`` (:meth:`plot`) and ``quadcruise.json`` (controller, vehicle, version).

        Parameters
        ----------
        out : str or path-like
            The folder; a non-empty one that quadcruise did not write is refused unless ``force``.
        force : bool
            Replace such a folder.
        progress : callable, optional
            ``progress(done, total)`` as the loops are drawn.

        Returns
        -------
        pathlib.Path
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
            save_figure(self.plot(progress=progress), tmp / "bode.png")
            marker = {
                "workflow": "analyze",
                "controller": self.controller,
                "vehicle": self.vehicle.to_dict(),
                "version": __version__,
            }
            (tmp / MARKER).write_text(dumps(marker) + "\n")
        return out


def _stable(T) -> bool:
    """Whether the closed loop's modes decay, the states it neither drives nor reads left out:
    repeatedly, a state that nothing else reads and the output does not show (a rate loop's
    angle, its integral the velocity), or that nothing drives (not the input, no other state)."""
    A, B, C = np.asarray(T.A, float), np.asarray(T.B, float).ravel(), np.asarray(T.C, float).ravel()
    keep = list(range(A.shape[0]))
    changed = True
    while changed:
        changed = False
        for j in list(keep):
            others = [i for i in keep if i != j]
            unread = C[j] == 0.0 and not np.any(A[others, j])
            undriven = B[j] == 0.0 and not np.any(A[j, others])
            if unread or undriven:
                keep.remove(j)
                changed = True
    return bool(np.max(np.abs(np.linalg.eigvals(A[np.ix_(keep, keep)])), initial=0.0) < 1.0)


def _phase(r):
    """The unwrapped phase [deg], whole turns taken off so that it starts within (-360, 0]."""
    ph = np.degrees(np.unwrap(np.angle(r)))
    return ph - 360.0 * math.ceil(ph[0] / 360.0)


SUMMARY_NOTES = (
    "Each loop is broken at its controller's output, the faster loops closed, the slower ones open. "
    "crossover: where |L| = 1; PM: phase margin; GM up/down: how far the loop gain may rise/fall "
    "[dB] (none: no limit); bandwidth: the closed loop's -3 dB frequency.",
    "Targets: PM >= {pm:g} deg and GM >= {gm:g} dB each way (classical floors: PX4 v1.15 states no "
    "margin); the rate loops' rise time (10-90 %) <= PX4 autotune's 0.14 s roll/pitch (MC_AT_RISE_TIME), "
    "0.2 s yaw. (!) marks what misses its target.",
)


def _text(rep: dict) -> str:
    def num(v, fmt):
        return "none" if v is None or not math.isfinite(v) else format(v, fmt)

    head = ["loop", "axis", "period", "crossover", "PM", "GM up", "GM down", "bandwidth", "rise", "verdict"]
    rows = [head, ["", "", "[ms]", "[rad/s]", "[deg]", "[dB]", "[dB]", "[rad/s] ([Hz])", "[s]", ""]]
    for loop, axes in rep["loops"].items():
        for axis, e in axes.items():
            verdict = "ok" if e["meets_margins"] else ("UNSTABLE (!)" if not e["stable"] else "margins short (!)")
            if loop == "rate" and not e["meets_rise_time"]:
                verdict += f", slower than {e['rise_time_target_s']:g} s (!)"
            rows.append(
                [
                    loop,
                    axis,
                    f"{1e3 * e['period_s']:g}",
                    num(e["crossover_rad_s"], ".3g"),
                    num(e["phase_margin_deg"], ".1f"),
                    num(e["gain_margin_up_db"], "+.1f"),
                    num(e["gain_margin_down_db"], "+.1f"),
                    f"{num(e['bandwidth_rad_s'], '.3g')} ({num(e['bandwidth_hz'], '.3g')})",
                    num(e.get("rise_time_s"), ".3f") if loop == "rate" else "",
                    verdict,
                ]
            )
    w = [max(len(r[j]) for r in rows) + 2 for j in range(len(head))]
    lines = [
        "".join(
            c.ljust(k) if j < 2 else ("  " + c if j == len(head) - 1 else c.rjust(k))
            for j, (c, k) in enumerate(zip(r, w, strict=True))
        )
        for r in rows
    ]
    pm, gm = TARGETS["phase_margin_deg"][0], TARGETS["gain_margin_db"][0]
    verdict = "every loop meets its margins" if rep["meets_margins"] else "margins short (!)"
    src = f" ({rep['params_source']})" if rep.get("params_source") else ""
    notes = [textwrap.fill(n.format(pm=pm, gm=gm), 100, subsequent_indent="  ") for n in SUMMARY_NOTES]
    return "\n".join([f"px4{src} about hover: {verdict}"] + lines + [""] + notes)
