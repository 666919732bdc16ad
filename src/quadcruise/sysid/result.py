"""What :func:`quadcruise.identify` returns: the parameters, their intervals, the validation.

Like every result: ``to_pandas()``, ``summary()``, ``plot()``, ``write(folder)``. The folder
holds ``identify.json``, ``vehicle.toml`` (a ``[vehicle]`` table of the paper's plant that
``quadcruise fly --scenario`` reads), ``report.md``, ``fit.png`` (measured against predicted on the
held-out tail) and ``quadcruise.json`` (the configuration and the command that wrote it).
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from quadcruise.metrics.summary import Summary
from quadcruise.model.vehicle import Vehicle

CHANNEL_LABELS = {
    "ax": "a_x world [m/s^2]",
    "ay": "a_y world [m/s^2]",
    "az": "a_z world [m/s^2]",
    "p_dot": "p' [rad/s^2]",
    "q_dot": "q' [rad/s^2]",
    "r_dot": "r' [rad/s^2]",
}
"""The validated channels and how figures label them."""


W_MAX_NOMINAL = 1000.0
"""The full-command rotor speed [rad/s] of a rotor-plant vehicle identified from commands alone
when the base vehicle gives none: the log determines the thrust at full command, ``kf w_max^2``,
not the speed (no rotor inertia or rotor drag is identified, so the speed's scale changes nothing
the plant does)."""
HOVER_DUTY_MEANING = (
    "each rotor's relative thrust at level hover (0-1, thrust over the thrust at full command: PX4's "
    "actuator_motors and hover_thrust_estimate), not the output signal x that THR_MDL_FAC f maps it to "
    "(f x^2 + (1 - f) x = hover_duty)"
)
"""What ``hover_duty`` means, written beside it in ``identify.json``."""
MASS_FIELDS = ("m", "K", "kf", "km", "Jxx", "Jyy", "Jzz", "k_d", "k_z", "J_rotor")
"""The vehicle fields that scale with the mass (absent from a vehicle identified without one)."""


def plus_arm(rotors: np.ndarray) -> float | None:
    """The arm [m] when ``rotors`` (x, y FLU, yaw sign) are the paper's four "+" rotors, else None.

    The paper's plant: rotors on +-x spin with yaw sign +1, on +-y with -1, all at one distance.

    Examples
    --------
    >>> plus = np.array([[-0.2, 0, 1], [0, 0.2, -1], [0.2, 0, 1], [0, -0.2, -1]])
    >>> plus_arm(plus), plus_arm(plus @ np.diag([0.7, 0.7, 1]) + np.array([[0, 0.14, 0]] * 4))
    (0.2, None)
    """
    rotors = np.asarray(rotors, dtype=float)
    if rotors.shape != (4, 3):
        return None
    arm = float(np.mean(np.hypot(rotors[:, 0], rotors[:, 1])))
    want = {(-1, 0, 1), (0, 1, -1), (1, 0, 1), (0, -1, -1)}
    have = {(round(x / arm), round(y / arm), int(np.sign(sgn))) for x, y, sgn in rotors} if arm > 0 else set()
    close = arm > 0 and np.allclose(np.abs(rotors[:, :2]).max(axis=1), arm, rtol=0.02)
    close = close and np.allclose(np.abs(rotors[:, :2]).min(axis=1), 0.0, atol=0.02 * arm)
    return arm if close and have == want else None


def rotor_equivalent(rotors: np.ndarray, values: dict, base, log_name: str):
    """A rotor-plant vehicle with ``rotors`` (x, y, yaw sign) and the paper plant's identified
    ``values`` (m, K per rotor, J, d, omega): ``kf = K / w_max^2``, ``km = d kf``,
    ``tau_up = tau_down = 1 / omega``, ``w_max`` the base's (:data:`W_MAX_NOMINAL` for a paper base).

    Examples
    --------
    >>> x = np.array([[0.15, -0.25, 1], [-0.15, 0.19, 1], [0.15, 0.25, -1], [-0.15, -0.19, -1]])
    >>> v = rotor_equivalent(x, {"m": 1.5, "K": 7.4, "Jxx": 0.03, "Jyy": 0.03, "Jzz": 0.05, "d": 0.05,
    ...                          "omega": 20.0}, Vehicle.paper(), "f.ulg")
    >>> round(v.kf * v.w_max**2, 6), v.n_rotors, v.tau_up
    (7.4, 4, 0.05)
    """
    from quadcruise.model.rotor_vehicle import RotorVehicle

    w_max = float(getattr(base, "w_max", W_MAX_NOMINAL))
    kf = values["K"] / w_max**2
    return RotorVehicle(
        m=values["m"],
        Jxx=values["Jxx"],
        Jyy=values["Jyy"],
        Jzz=values["Jzz"],
        kf=kf,
        km=values["d"] * kf,
        tau_up=1.0 / values["omega"],
        tau_down=1.0 / values["omega"],
        w_min=0.0,
        w_max=w_max,
        rotors=tuple((float(x), float(y), 0.0, int(np.sign(sgn))) for x, y, sgn in rotors),
        g=float(base.g),
        source=f"identified from {log_name} by quadcruise identify (commands alone: kf w_max^2 = K)",
    )


@dataclass(frozen=True, eq=False)
class IdentifyResult:
    """An identified vehicle.

    Parameters
    ----------
    parameters : dict
        Name -> ``{"value", "ci95": [lo, hi], "unit", "identifiable", "source"}`` (and
        ``note``, ``estimate`` for one the log could not identify: its value is then the base
        vehicle's and its interval ``[None, None]``). ``hover_duty`` is one of them.
    validation : dict
        Held-out channel -> ``{"r2", "rmse", "unit"}``; ``open_loop`` for the rates predicted
        over short windows.
    traces : dict
        ``t`` and channel -> (measured, predicted) on the held-out samples.
    log : dict
        What was read: file, airborne time, grid, commands, resampling, topic rates.
    fit : dict
        How it was fitted: rows, filter, Newey-West bandwidth, coefficients.
    base : Vehicle
        The base vehicle.
    mass : float or None
        The mass given [kg]; None: K and the inertias are per unit mass.
    rotors : ndarray
        The rotor geometry used (x, y [m] FLU, yaw sign).
    command : str
        The command line that produced it (set by the CLI; empty from Python).
    verdict : dict
        Whether the model fits the log (:func:`quadcruise.sysid.verdict.judge`): ``verdict``
        (``"fits"`` or ``"does not fit"``), ``fits``, ``reasons``, ``checks``.
    """

    parameters: dict
    validation: dict
    traces: dict
    log: dict
    fit: dict
    base: Vehicle
    mass: float | None
    rotors: np.ndarray
    command: str = field(default="")
    verdict: dict = field(default_factory=dict)

    @property
    def fits(self) -> bool:
        """Whether the model fits the log (:mod:`quadcruise.sysid.verdict`): True when no check failed."""
        return bool(self.verdict.get("fits", True))

    def verdict_line(self) -> str:
        """The verdict in one line: ``verdict: the model fits the log`` or why it does not.

        Returns
        -------
        str
        """
        if not self.verdict:
            return "verdict: not judged"
        if self.fits:
            names = {
                "held_out": "held out",
                "white": "white residuals",
                "segments": "segments agree",
                "commands": "the commands all logged or unchanged between samples",
                "structure": "its lag fits better than the other",
            }
            checks = self.verdict.get("checks", {})
            if checks.get("commands", {}).get("control_hz", 0) is None:
                names["commands"] = "the log does not say its control rate: its commands held between changes"
            done = [names.get(k, k) for k in checks]
            return f"verdict: the model fits the log ({', '.join(done)})"
        return "verdict: the model DOES NOT FIT the log, no intervals: " + "; ".join(self.verdict["reasons"])

    @property
    def hover_duty(self) -> float:
        """Each rotor's relative thrust (0-1, thrust over the thrust at full command) that holds
        level hover [-]: PX4's ``actuator_motors`` and ``hover_thrust_estimate`` units on every
        path (paper or rotor plant, with or without rotor speeds), not the output signal x that
        ``THR_MDL_FAC`` makes of it (``f x^2 + (1 - f) x`` = this)."""
        return float(self.parameters["hover_duty"]["value"])

    def vehicle(self, mass: float | None = None):
        """The vehicle the log flew: the identified values, the log's rotors, the base vehicle's
        values only for what the log could not tell.

        A log whose rotors are the paper's four "+" ones (``CA_ROTOR*``, or none: the base's) gives
        the paper's plant (``l`` the rotors' distance); any other layout (x, hexa, ...) a
        rotor-plant vehicle with the log's rotors, ``kf = K / w_max^2``, ``km = d kf`` and
        ``tau_up = tau_down = 1 / omega`` (:func:`rotor_equivalent`). A rotor-plant base vehicle
        gives its plant's fields. No mass is invented: without one (here or given to identify)
        this refuses.

        Parameters
        ----------
        mass : float, optional
            The mass [kg] when identify had none (the per-unit-mass values are scaled by it).

        Returns
        -------
        Vehicle or RotorVehicle

        Raises
        ------
        InputError
            No mass, here or in the identification.
        """
        from quadcruise.errors import InputError

        m = mass if mass is not None else self.mass
        if m is None:
            raise InputError(
                "the log gives no mass and identify had none: K and the inertias are per unit mass; "
                "give it (vehicle(mass=KG), or identify --mass KG)"
            )
        return self._vehicle(float(m))

    @property
    def plant(self):
        """The plant identified (:mod:`quadcruise.sim.plants`): the fit's ``plant``, the paper's by default."""
        from quadcruise.sim import plants

        return plants.named(self.fit.get("plant"))

    def _vehicle(self, m: float):
        return VEHICLES[self.plant.name](self, m)

    def _rotor_vehicle(self, m: float):
        """A RotorVehicle: the identified fields, the log's rotors, the base's for the rest."""
        values: dict[str, Any] = {"m": m}
        scale = 1.0 if self.mass is not None else m
        for name in ("kf", "km", "Jxx", "Jyy", "Jzz", "k_d", "k_z", "J_rotor", "tau_up", "tau_down", "w_max"):
            key = name if self.mass is not None or name in ("tau_up", "tau_down", "w_max") else f"{name}_per_m"
            if key in self.parameters:
                per_m = key.endswith("_per_m")
                values[name] = float(self.parameters[key]["value"]) * (scale if per_m else 1.0)
        values["rotors"] = tuple(tuple(float(x) for x in row[:3]) + (int(row[3]),) for row in self.rotors)
        values["source"] = f"identified from {Path(self.log['source']).name} (base: {self.base.source or 'a file'})"
        return self.base.replace(**values)

    def _paper_vehicle(self, m: float):
        """A paper Vehicle where the log's rotors are a "+", else a rotor-plant vehicle from the
        commands alone (:func:`rotor_equivalent`)."""
        values: dict[str, Any] = {"m": m}
        scale = 1.0 if self.mass is not None else m
        for name in ("K", "Jxx", "Jyy", "Jzz"):
            key = name if self.mass is not None else f"{name}_per_m"
            values[name] = float(self.parameters[key]["value"]) * scale
        for name in ("d", "omega"):
            values[name] = float(self.parameters[name]["value"])
        arm = plus_arm(self.rotors)
        if arm is not None:
            values["l"] = arm
            return self.base.replace(**{k: v for k, v in values.items()})
        return rotor_equivalent(self.rotors, values, self.base, Path(self.log["source"]).name)

    def to_pandas(self):
        """One row per identified parameter (not per sample: the held-out samples are in :attr:`traces`).

        Returns
        -------
        pandas.DataFrame
            One row per parameter: value, ci95_low, ci95_high, unit, identifiable, source.
        """
        import pandas as pd

        rows = [
            {
                "parameter": k,
                "value": v["value"],
                "ci95_low": v["ci95"][0],
                "ci95_high": v["ci95"][1],
                "unit": v["unit"],
                "identifiable": v["identifiable"],
                "source": v["source"],
            }
            for k, v in self.parameters.items()
        ]
        return pd.DataFrame(rows)

    def summary(self) -> Summary:
        """The headline numbers: each parameter with its interval, and the validation scores.

        Returns
        -------
        Summary
            Keys ``parameters`` (name -> value), ``identifiable`` (names), ``hover_duty``,
            ``validation_r2`` (channel -> R^2); prints as a table.
        """
        lines = [
            self.verdict_line(),
            (
                f"{self.log['source']}: {self.log['airborne_s']:.1f} s airborne, "
                f"{'mass ' + format(self.mass, 'g') + ' kg' if self.mass is not None else 'no mass given'}"
            ),
        ]
        if self.mass is None:
            lines.append("  no mass: K and the inertias are per unit mass (_per_m)")
        for name, p in self.parameters.items():
            if p["identifiable"]:
                ci = f"[{p['ci95'][0]:.4g}, {p['ci95'][1]:.4g}]"
                lines.append(f"  {name:<16} {p['value']:>11.5g} {p['unit']:<7} 95 % {ci}")
            else:
                lines.append(f"  {name:<16} {p['value']:>11.5g} {p['unit']:<7} not identifiable ({p['note']})")
        lines += [f"  caution: {c}" for c in self.fit.get("cautions", [])]
        r2 = {k: v["r2"] for k, v in self.validation.items() if k in CHANNEL_LABELS}
        lines.append("  held-out R^2: " + ", ".join(f"{k} {v:.3f}" for k, v in r2.items()))
        data = {
            "verdict": self.verdict.get("verdict"),
            "parameters": {k: v["value"] for k, v in self.parameters.items()},
            "identifiable": [k for k, v in self.parameters.items() if v["identifiable"]],
            "hover_duty": self.hover_duty,
            "validation_r2": r2,
        }
        return Summary(data, "\n".join(lines))

    def plot(self):
        """Measured against predicted on the held-out tail, one panel per channel.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from matplotlib.figure import Figure

        fig = Figure(figsize=(11, 6.5), layout="constrained")
        axes = fig.subplots(2, 3, sharex=True)
        t = self.traces["t"]
        for ax, name in zip(axes.ravel(), CHANNEL_LABELS, strict=False):
            measured, predicted = self.traces[name]
            ax.plot(t, measured, lw=0.8, color="0.3", label="measured")
            ax.plot(t, predicted, lw=0.8, color="tab:red", label="predicted")
            ax.set_title(f"{CHANNEL_LABELS[name]}   R² {self.validation[name]['r2']:.3f}", fontsize=9)
        for ax in axes[1]:
            ax.set_xlabel("t [s]")
        axes[0, 0].legend(fontsize=8)
        fig.suptitle(f"held-out {self.fit['holdout']:g} of {Path(self.log['source']).name}", fontsize=10)
        return fig

    def to_json(self) -> dict:
        """``identify.json``'s content.

        Returns
        -------
        dict
            ``verdict`` (and its reasons and checks), ``covariance`` (the identified parameters'
            joint covariance, ``{"names", "matrix"}``, or None), ``parameters``, ``hover_duty``,
            ``mass_kg``, ``per_unit_mass``, ``validation``, ``log``, ``fit``, ``command``.
        """
        from quadcruise.io.plainjson import plain

        return plain(
            {
                "verdict": self.verdict.get("verdict"),
                "verdict_reasons": self.verdict.get("reasons", []),
                "verdict_checks": self.verdict.get("checks", {}),
                "covariance": self.fit.get("covariance") if self.fits else None,
                "parameters": {
                    k: {kk: vv for kk, vv in v.items()} | ({"meaning": HOVER_DUTY_MEANING} if k == "hover_duty" else {})
                    for k, v in self.parameters.items()
                },
                "hover_duty": self.hover_duty,
                "hover_duty_meaning": HOVER_DUTY_MEANING,
                "mass_kg": self.mass,
                "per_unit_mass": self.mass is None,
                "validation": self.validation,
                "log": self.log,
                "fit": self.fit,
                "command": self.command,
                "base_vehicle": self.base.to_dict(),
            }
        )

    def vehicle_toml(self) -> str:
        """The identified vehicle as a ``[vehicle]`` table (:meth:`vehicle`).

        Without a mass, ``m`` and each field that scales with it hold a string saying so (the
        value per unit mass for the latter): ``quadcruise fly`` refuses the file, in one line,
        until they are numbers.

        Returns
        -------
        str
            TOML that ``quadcruise fly --vehicle`` reads.
        """
        import tomli_w

        from quadcruise.sim import plants

        v = self._vehicle(float(self.mass) if self.mass is not None else 1.0)
        written = plants.of(v)  # a paper fit of rotors that are not a "+" writes a rotor-plant vehicle
        origin = {
            k.removesuffix("_per_m"): ("identified" if p["identifiable"] else p.get("source", "base vehicle"))
            for k, p in self.parameters.items()
            if k not in ("hover_speed", "hover_duty", "thrust_curve_f")
        }
        head = [
            f"# {self.verdict_line()}",
            f"# identified from {self.log['source']} by quadcruise identify ({written.name} plant)",
            "# " + ", ".join(f"{k}: {s}" for k, s in origin.items()),
            f"# rotors: {self.log['rotor_geometry']}; the rest: the base vehicle's",
        ]
        if written is not self.plant:
            head.append(
                "# the log's rotors are not the paper's '+': a rotor-plant vehicle from the commands alone, "
                f"kf w_max^2 = K, km = d kf, tau = 1/omega, w_max {v.w_max:g} rad/s (not in the log)"
            )
        fields = written.file_fields({k: x for k, x in v.to_dict().items() if x is not None})
        if self.mass is None:
            head.append(
                "# NO MASS: identify ran without --mass. m and the fields marked 'per unit mass' are strings: "
                "write the mass [kg] in m and each such field's number times it (or identify again with --mass)"
            )
            for key in MASS_FIELDS[1:]:
                if key in fields and isinstance(fields[key], float) and fields[key] != 0.0:
                    fields[key] = f"{fields[key]:.6g} per unit mass: times m [kg]"
            fields["m"] = "unknown: identify ran without --mass; write the vehicle's mass [kg]"
            order = ["preset", "plant", "m"]
            fields = {k: fields[k] for k in order if k in fields} | {k: x for k, x in fields.items() if k not in order}
        return "\n".join(head) + "\n" + tomli_w.dumps({"vehicle": fields})

    def report_md(self) -> str:
        """The report, in Markdown.

        Returns
        -------
        str
        """
        lines = [
            f"# Identified vehicle: {Path(self.log['source']).name}",
            "",
            f"**{self.verdict_line()}**",
            "",
            (
                f"- log: `{self.log['source']}`, {self.log['airborne_s']:.1f} s airborne in "
                f"{self.log['segments']} segment(s), on a {self.log['grid_hz']:.0f} Hz grid"
            ),
            f"- resampling: {self.log['resampling']}",
            f"- commands: {self.log['commands']}",
            f"- rotor geometry: {self.log['rotor_geometry']}",
            f"- mass: {self.mass} kg"
            if self.mass is not None
            else "- mass: not given; K and the inertias are **per unit mass** (`_per_m`)",
            (
                f"- fit: first {1 - self.fit['holdout']:.0%} of the airborne samples ({self.fit['rows']}), "
                f"Savitzky-Golay window {self.fit['window_s']:.3f} s, Newey-West bandwidth "
                f"{self.fit['newey_west_bandwidth']} samples"
            ),
            "",
            "| parameter | value | 95 % interval | unit | identifiable | note |",
            "|---|---|---|---|---|---|",
        ]
        for name, p in self.parameters.items():
            ci = f"[{p['ci95'][0]:.4g}, {p['ci95'][1]:.4g}]" if p["identifiable"] else "-"
            value = f"{p['value']:.5g}" + ("" if p["identifiable"] else f" ({p['source']})")
            lines.append(
                f"| {name} | {value} | {ci} | {p['unit']} | {'yes' if p['identifiable'] else 'no'} "
                f"| {p.get('note', '')} |"
            )
        if self.fit.get("cautions"):
            lines += [""] + [f"**Caution**: {c}" for c in self.fit["cautions"]]
        if "px4_hover_thrust_estimate" in self.log:
            lines += [
                "",
                (f"PX4's own hover_thrust_estimate in this log (median): {self.log['px4_hover_thrust_estimate']:.4f}"),
            ]
        lines += [
            "",
            f"## Held-out validation (last {self.fit['holdout']:.0%})",
            "",
            "| channel | R² | RMSE | unit |",
            "|---|---|---|---|",
        ]
        for name in CHANNEL_LABELS:
            v = self.validation[name]
            lines.append(f"| {name} | {v['r2']:.4f} | {v['rmse']:.4g} | {v['unit']} |")
        low = [name for name in CHANNEL_LABELS if not self.validation[name]["r2"] >= 0.5]
        if low:
            lines += [
                "",
                (
                    f"R² below 0.5 on {', '.join(low)}: the held-out tail moves little there (or the model "
                    "misses something); read the RMSE against the sensors' noise before trusting either."
                ),
            ]
        ol = self.validation["open_loop"]
        lines += [
            "",
            f"Open loop over {ol['windows']} windows of {ol['window_s']:.3f} s (rates at the window's end):",
            "",
        ]
        for name in "pqr":
            if name in ol:
                lines.append(f"- {name}: R² {ol[name]['r2']:.4f}, RMSE {ol[name]['rmse']:.4g} rad/s")
        lines += ["", "![measured against predicted](fit.png)", ""]
        if self.command:
            lines += [f"Written by: `{self.command}`", ""]
        return "\n".join(lines)

    def write(self, folder: str | os.PathLike, *, force: bool = False) -> Path:
        """Write the folder, whole or not at all.

        Parameters
        ----------
        folder : str or os.PathLike
            The folder: ``identify.json``, ``vehicle.toml``, ``report.md``, ``fit.png``,
            ``quadcruise.json``.
        force : bool
            Replace a non-empty folder quadcruise did not write (a folder holding the log read is
            refused all the same: writing it would delete the log).

        Returns
        -------
        pathlib.Path
            The folder.

        Raises
        ------
        InputError
            Before anything is written: ``folder`` holds the log (or is not writable, or holds
            something else, unless ``force``).
        """
        from quadcruise._version import __version__
        from quadcruise.io.files import MARKER, atomic_dir, check_output_dir

        out = check_output_dir(folder, force, inputs=[self.log.get("source")])
        with atomic_dir(out) as tmp:
            tmp = Path(tmp)
            (tmp / "identify.json").write_text(json.dumps(self.to_json(), indent=2) + "\n")
            (tmp / "vehicle.toml").write_text(self.vehicle_toml())
            (tmp / "report.md").write_text(self.report_md())
            self.plot().savefig(tmp / "fit.png", dpi=110)
            marker: dict[str, Any] = {
                "workflow": "identify",
                "version": __version__,
                "command": self.command,
                "log": self.log["source"],
                "mass_kg": self.mass,
                "holdout": self.fit["holdout"],
                "commands": self.log["commands"],
                "base_vehicle": self.base.to_dict(),
            }
            (tmp / MARKER).write_text(json.dumps(marker, indent=2) + "\n")
        return out


VEHICLES = {"paper": IdentifyResult._paper_vehicle, "rotor": IdentifyResult._rotor_vehicle}
"""The vehicle an identification writes, by the plant identified (``fit["plant"]``, the paper's by default)."""
