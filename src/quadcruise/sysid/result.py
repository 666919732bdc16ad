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

    @property
    def hover_duty(self) -> float:
        """The per-rotor command that holds level hover [-]."""
        return float(self.parameters["hover_duty"]["value"])

    def vehicle(self) -> Vehicle:
        """The identified vehicle in the paper's plant, or for a rotor-plant base vehicle a
        RotorVehicle with the log's rotors (base values where the log could not tell).

        Without a mass, the base vehicle's mass scales the per-unit-mass values. The paper's
        plant has four "+" rotors at distance ``l``: ``l`` is the log's mean rotor distance,
        and a log with n != 4 rotors gets ``K`` scaled by n/4 so that the total thrust and the
        hover hold (its moments then only approximate the real layout's).

        Returns
        -------
        Vehicle
        """
        m = float(self.mass) if self.mass is not None else float(self.base.m)
        values: dict[str, float] = {"m": m}
        if self.fit.get("plant") == "rotor":  # a RotorVehicle: the identified fields, the log's rotors
            for name in ("kf", "km", "Jxx", "Jyy", "Jzz", "k_d", "k_z", "J_rotor", "tau_up", "tau_down", "w_max"):
                key = name if self.mass is not None or name in ("tau_up", "tau_down", "w_max") else f"{name}_per_m"
                if key in self.parameters:
                    per_m = key.endswith("_per_m")
                    values[name] = float(self.parameters[key]["value"]) * (m if per_m else 1.0)
            values["rotors"] = tuple(tuple(float(x) for x in row[:3]) + (int(row[3]),) for row in self.rotors)
            values["source"] = f"identified from {Path(self.log['source']).name} (base: {self.base.source or 'a file'})"
            return self.base.replace(**values)
        for name in ("K", "Jxx", "Jyy", "Jzz"):
            key = name if self.mass is not None else f"{name}_per_m"
            values[name] = float(self.parameters[key]["value"]) * (1.0 if self.mass is not None else m)
        for name in ("d", "omega"):
            values[name] = float(self.parameters[name]["value"])
        values["K"] *= len(self.rotors) / 4.0
        arm = float(np.mean(np.hypot(self.rotors[:, 0], self.rotors[:, 1])))
        values["l"] = arm
        return self.base.replace(**values)

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
            (
                f"{self.log['source']}: {self.log['airborne_s']:.1f} s airborne, "
                f"{'mass ' + format(self.mass, 'g') + ' kg' if self.mass is not None else 'no mass given'}"
            )
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
            ``parameters``, ``hover_duty``, ``mass_kg``, ``per_unit_mass``, ``validation``,
            ``log``, ``fit``, ``command``.
        """
        from quadcruise.io.plainjson import plain

        return plain(
            {
                "parameters": {k: {kk: vv for kk, vv in v.items()} for k, v in self.parameters.items()},
                "hover_duty": self.hover_duty,
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
        """The identified vehicle as a ``[vehicle]`` table.

        Returns
        -------
        str
            TOML that ``quadcruise fly --scenario`` reads.
        """
        import tomli_w

        v = self.vehicle()
        if self.fit.get("plant") == "rotor":
            origin = {
                k.removesuffix("_per_m"): ("identified" if p["identifiable"] else "base vehicle")
                for k, p in self.parameters.items()
                if k not in ("hover_speed", "hover_duty")
            }
            head = [
                f"# identified from {self.log['source']} by quadcruise identify (rotor plant)",
                "# " + ", ".join(f"{k}: {s}" for k, s in origin.items()),
                f"# m: {'given' if self.mass is not None else 'base vehicle (no mass given: kf, km, J scaled by it)'}"
                f"; rotors: {self.log['rotor_geometry']}; the rest: the base vehicle's",
            ]
            fields = {k: x for k, x in v.to_dict().items() if x is not None}
            return "\n".join(head) + "\n" + tomli_w.dumps({"vehicle": {"plant": "rotor", **fields}})
        origin = {}
        for name in ("K", "Jxx", "Jyy", "Jzz", "d", "omega"):
            key = name if self.mass is not None or name in ("d", "omega") else f"{name}_per_m"
            origin[name] = "identified" if self.parameters[key]["identifiable"] else "base vehicle"
        head = [
            f"# identified from {self.log['source']} by quadcruise identify",
            "# " + ", ".join(f"{k}: {s}" for k, s in origin.items()),
            (
                f"# m: {'given' if self.mass is not None else 'base vehicle (no mass given: K, J scaled by it)'}"
                f"; l: mean rotor distance of the {self.log['rotor_geometry']}"
            ),
        ]
        if len(self.rotors) != 4:
            head.append(
                f"# the log's vehicle has {len(self.rotors)} rotors, the paper's plant 4: K scaled by "
                f"{len(self.rotors)}/4 (same total thrust and hover; moments approximate)"
            )
        body = tomli_w.dumps({"vehicle": {"preset": "paper", **{k: float(x) for k, x in v.to_dict().items()}}})
        return "\n".join(head) + "\n" + body

    def report_md(self) -> str:
        """The report, in Markdown.

        Returns
        -------
        str
        """
        lines = [
            f"# Identified vehicle: {Path(self.log['source']).name}",
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
            Replace a non-empty folder quadcruise did not write.

        Returns
        -------
        pathlib.Path
            The folder.
        """
        from quadcruise._version import __version__
        from quadcruise.io.files import MARKER, atomic_dir, check_output_dir

        out = check_output_dir(folder, force)
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
