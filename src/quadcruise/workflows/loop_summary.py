"""A linearised loop's summary: each loop's poles, damping and margins beside the design's poles,
as plain values and as an aligned text table."""

from __future__ import annotations

import math
import textwrap
from collections.abc import Callable

import numpy as np

from quadcruise.metrics.margins import MIN_GAIN_MARGIN_DB, MIN_PHASE_MARGIN_DEG, low_margins

__all__ = ["DESIGN", "SUMMARY_NOTES", "summary_data", "summary_text"]

DESIGN = {"x": "position", "y": "position", "z": "altitude", "yaw": "yaw"}
"""The controller attribute with each loop's design gains (``.poles``), where it has one."""


def summary_data(lin, progress: Callable[[int, int], None] | None = None) -> dict:
    """Poles, damping and margins of every loop beside the design's poles, as plain values (the keys:
    docs/paper.md, "Linear analysis of the full loop")."""
    controller = lin.controller
    out = {
        "controller": getattr(controller, "name", "controller"),
        "dt_s": lin.dt,
        "stable": lin.stable,
        "spectral_radius": float(np.max(np.abs(lin.poles()))),
        "hover_residual": lin.residual,
        "loops": {},
    }
    if progress is not None:
        progress(0, len(lin.loops))
    for k, loop in enumerate(lin.loops):
        p, weight = lin.loop_modes(loop)
        p, weight = p[p.imag >= 0], np.where(p.imag > 0, 2.0, 1.0)[p.imag >= 0] * weight[p.imag >= 0]
        # control.damp does not serve: it recomputes the poles in its own order (not paired with
        # their weights) and gives NaN damping for a pole at z = 0, which dies in one period
        wn = np.abs(p)
        with np.errstate(invalid="ignore"):
            zeta = np.where(np.isinf(wn), 1.0, -p.real / np.where(wn > 0, wn, 1.0))
        dom = p[np.argmax(weight)]
        margins = {at: lin.margins(loop, at) for at in ("input", "output")}
        entry = out["loops"][loop] = {
            "poles": [[round(float(z.real), 6), round(float(z.imag), 6)] for z in p],
            "natural_frequency": wn.tolist(),
            "damping": zeta.tolist(),
            "step_weight": weight.tolist(),
            "dominant": [round(float(dom.real), 6), round(float(dom.imag), 6)],
            "slowest": [round(float(p[0].real), 6), round(float(p[0].imag), 6)],
            "min_damping": float(zeta.min()),
            "margins_input": margins["input"],
            "margins_output": margins["output"],
            "low_margins": {at: low_margins(m) for at, m in margins.items()},
        }
        design = getattr(getattr(controller, DESIGN[loop], None), "poles", None)
        if design is not None:
            d = np.atleast_1d(np.asarray(design, complex)).round(9)
            d = d[d.imag >= 0]  # one of each pair, as the poles
            near = [p[np.argmin(np.abs(p - z))] for z in d]
            entry["design_poles"] = [float(z.real) if z.imag == 0 else [float(z.real), float(z.imag)] for z in d]
            entry["nearest"] = [[float(q.real), float(q.imag)] for q in near]
            entry["nearest_rel_distance"] = [float(abs(q - z) / abs(z)) for q, z in zip(near, d, strict=False)]
        if progress is not None:
            progress(k + 1, len(lin.loops))
    return out


SUMMARY_NOTES = (
    (
        "dominant: the pole (a complex pair counted as one mode) with the largest weight in the loop's step "
        "response; slowest: the least decay rate."
    ),
    (
        "GM down / up: how far the loop gain may fall / rise before the loop goes unstable [dB]; a loop with a GM "
        "down is conditionally stable (stable at its gain, unstable at a lower one, e.g. a PID's integral on a "
        "double integrator); none: no limit that way."
    ),
    f"(!): below {MIN_PHASE_MARGIN_DEG:g} deg of phase margin or within {MIN_GAIN_MARGIN_DB:g} dB of 0 dB.",
)
"""The lines :func:`summary_text` ends with: what its rows mean."""


def summary_text(rep: dict) -> str:
    """:func:`summary_data` as an aligned text table, one column per loop."""

    def pole(p):
        return f"{p[0]:.3g}" if p[1] == 0 else f"{p[0]:.3g}±{p[1]:.3g}j"

    def design(e):
        return (
            ", ".join(
                f"{z if isinstance(z, float) else complex(*z)}:{d:.0%}"
                for z, d in zip(e.get("design_poles", []), e.get("nearest_rel_distance", []), strict=False)
            )
            or "-"
        )

    def pm(m):
        short = " (!)" if m["phase_margin"] < MIN_PHASE_MARGIN_DEG else ""
        return f"{m['phase_margin']:.1f}{short} @ {m['gain_crossover']:.3g}"

    def gm(m):
        down, up = m["gain_decrease_db"], m["gain_increase_db"]
        down = "none" if not math.isfinite(down) else f"{down:+.3g}" + (" (!)" if down > -MIN_GAIN_MARGIN_DB else "")
        up = "none" if not math.isfinite(up) else f"{up:+.3g}" + (" (!)" if up < MIN_GAIN_MARGIN_DB else "")
        return f"{down}, {up}"

    rows = [
        ("dominant pole [rad/s]", lambda e: pole(e["dominant"])),
        ("slowest pole [rad/s]", lambda e: pole(e["slowest"])),
        ("min damping", lambda e: f"{e['min_damping']:.3f}"),
        ("design poles: nearest off by", design),
    ]
    for at in ("input", "output"):
        rows += [
            (f"PM at the {at} [deg] @ [rad/s]", lambda e, m="margins_" + at: pm(e[m])),
            (f"GM at the {at} [dB]: down, up", lambda e, m="margins_" + at: gm(e[m])),
        ]
    table = [[""] + list(rep["loops"])] + [[name] + [cell(e) for e in rep["loops"].values()] for name, cell in rows]
    w = [max(len(row[j]) for row in table) + 2 for j in range(len(table[0]))]
    short = [loop for loop, e in rep["loops"].items() if any(e.get("low_margins", {}).values())]
    verdict = (
        "stable (every pole inside the unit circle)"
        if rep["stable"]
        else "UNSTABLE (a pole on or outside the unit circle)"
    )
    head = f"{rep['controller']} about hover, dt = {rep['dt_s']:g} s: {verdict}"
    if short:
        head += f", margins short on {', '.join(short)} (!)"
    return "\n".join(
        [head]
        + [r[0].ljust(w[0]) + "".join(c.rjust(k) for c, k in zip(r[1:], w[1:], strict=False)) for r in table]
        + [""]
        + [textwrap.fill(note, 100, subsequent_indent="  ") for note in SUMMARY_NOTES]
    )
