"""Controllers side by side: one mission, one vehicle, the same engine, their metrics and paths.

Examples
--------
>>> from quadcruise.workflows.compare import compare
>>> cmp = compare("step", ("nlpd", "se3", "cascade"), duration=4.0, log_every=10)
>>> list(cmp.results)
['nlpd', 'se3', 'cascade']
>>> table = cmp.metrics()
>>> table.index.tolist(), bool(table["status"].eq("finished").all())
(['nlpd', 'se3', 'cascade'], True)
>>> [ax.get_ylabel() for ax in cmp.plot().axes]
['y [m]', 'x [m]', 'y [m]', 'z [m]', 'position error [m]']
"""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from quadcruise import checks
from quadcruise.control import Controller, as_controller, controller_record
from quadcruise.control.registry import compared_names
from quadcruise.errors import InputError, reject_unknown
from quadcruise.io.plainjson import dumps, plain
from quadcruise.metrics.summary import Summary
from quadcruise.missions import Mission, as_mission
from quadcruise.model.rotor_vehicle import RotorVehicle
from quadcruise.model.vehicle import Vehicle
from quadcruise.sim import plants
from quadcruise.workflows.fly import fly
from quadcruise.workflows.fly_failures import flight_warnings_named
from quadcruise.workflows.fly_inputs import FLY_OPTIONS
from quadcruise.workflows.onboard import onboard_inputs, vehicle_gravity
from quadcruise.workflows.rotor_fly import as_vehicle, flight_setup

__all__ = ["compare", "Comparison", "DEFAULT_CONTROLLERS"]

DEFAULT_CONTROLLERS = ("nlpd", "gonzalez", "se3", "cascade")
"""The built-in controllers compare flies by default: the paper's controller, its reconstructed
baseline, geometric SE(3) and the PX4 cascade (with any controller declared since with
``compared=True``: :func:`quadcruise.control.registry.compared_names`)."""


@dataclass(frozen=True, eq=False)
class Comparison:
    """Flights of several controllers on the same mission and vehicle.

    :func:`compare` builds it.

    Parameters
    ----------
    mission : Mission
        The mission every controller flew.
    controllers : dict of str to Controller
        Label -> controller, in the order flown.
    results : dict of str to SimResult
        Label -> flight, in the same order.
    population : dict
        The Monte Carlo population the controllers also flew, as a scenario's ``[compare]
        population`` records it (``n``, ``seed``, the spreads); empty if none.
    population_table : pandas.DataFrame, optional
        Its table (:func:`quadcruise.montecarlo.compare.compare_population`), one row per controller.
    """

    mission: Mission
    controllers: dict
    results: dict
    population: dict = field(default_factory=dict)
    population_table: Any = None
    _tables: dict = field(default_factory=dict, init=False, repr=False)  # metrics() per keywords

    @property
    def ok(self) -> dict:
        """Label -> True where every vehicle of that controller flew the whole mission (finished).

        Returns
        -------
        dict of str to bool
        """
        return {label: bool(res.ok.all()) for label, res in self.results.items()}

    @property
    def failed(self) -> dict:
        """Label -> why its first unfinished vehicle stopped, for each controller that did not finish.

        Returns
        -------
        dict of str to str
            Empty when every flight finished; e.g. ``{"fast": "lost track: the position error
            left the tracking bound at t = 3.2480 s"}``.
        """
        out = {}
        for label, res in self.results.items():
            bad = np.flatnonzero(~res.ok)
            if bad.size:
                more = f" ({bad.size} of {res.n} vehicles)" if res.n > 1 else ""
                out[label] = res.status_text(int(bad[0])) + more
        return out

    def metrics(self, **metric_kw: Any):
        """The metrics of every flight, one row per controller (per controller and vehicle for a batch).

        Computed once per set of keywords (the text, the files and a report share it).

        Parameters
        ----------
        **metric_kw : Any
            Keywords of :func:`quadcruise.metrics.flight_metrics`: ``transient_axis``,
            ``transient_until``, and the conventions ``rise`` (e.g. ``(0.0, 1.0)`` for
            0-100 %) and ``settle_bands`` (e.g. ``(0.02, 0.03)``).

        Returns
        -------
        pandas.DataFrame
            Every column of :func:`quadcruise.metrics.flight_metrics`, indexed by
            controller (by controller and vehicle for a batch); a copy. Its
            ``attrs["conventions"]`` records the conventions.
        """
        key = repr(sorted(metric_kw.items()))
        if key not in self._tables:
            self._tables[key] = self._table(metric_kw)
        return self._tables[key].copy()

    def table(self, **metric_kw: Any):
        """Old name of :meth:`metrics`, kept for existing code.

        Parameters
        ----------
        **metric_kw : Any
            Keywords of :meth:`metrics`.

        Returns
        -------
        pandas.DataFrame
            :meth:`metrics`.
        """
        return self.metrics(**metric_kw)

    def _table(self, metric_kw: dict):
        import pandas as pd

        frames = []
        for label, res in self.results.items():
            frame = res.metrics(**metric_kw)
            frame.insert(0, "controller", label)
            frames.append(frame)
        table = pd.concat(frames, ignore_index=True)
        table.attrs = dict(frames[0].attrs)
        if all(res.n == 1 for res in self.results.values()):
            return table.drop(columns="vehicle").set_index("controller")
        return table.set_index(["controller", "vehicle"])

    def to_pandas(self):
        """The traces, long-form: one row per controller, vehicle and logged instant (per-flight: :meth:`metrics`).

        Returns
        -------
        pandas.DataFrame
            Columns ``controller``, ``vehicle``, ``t``, the states, references and commands.
        """
        import pandas as pd

        frames = []
        for label, res in self.results.items():
            frame = res.to_pandas()
            frame.insert(0, "controller", label)
            frames.append(frame)
        return pd.concat(frames, ignore_index=True)

    def summary(self, **metric_kw: Any) -> Summary:
        """The metrics of each controller; prints as :meth:`text`.

        Parameters
        ----------
        **metric_kw
            Keywords of :func:`quadcruise.metrics.flight_metrics`.

        Returns
        -------
        Summary
            Controller label -> {metric: value} (NaN as None), as in :meth:`to_dict`'s ``metrics``.
        """
        return Summary(self._rows(self.metrics(**metric_kw)), self.text(**metric_kw))

    def text(self, **metric_kw: Any) -> str:
        """The metrics as aligned text, metrics down and controllers across (for a terminal).

        A missing settling time of a measured transient reads "did not settle".

        Parameters
        ----------
        **metric_kw : Any
            Keywords of :meth:`metrics`.

        Returns
        -------
        str
            See :func:`quadcruise.metrics.tables.metrics_text`; below the table, what its
            columns measure (:func:`quadcruise.metrics.tables.conventions_text`).
        """
        from quadcruise.metrics.tables import conventions_text, metrics_text

        table = self.metrics(**metric_kw)
        text = metrics_text(table, [" ".join(map(str, c)) if isinstance(c, tuple) else c for c in table.index])
        notes = "\n".join(n for n in (conventions_text(table.attrs.get("conventions")), self.flown_on()) if n)
        return f"{text}\n{notes}" if notes else text

    def flown_on(self) -> str:
        """What the controllers read: "" on the truth; else a line naming the estimator and sensors.

        Returns
        -------
        str
            E.g. ``controllers flew on the estimate: ekf on imu, gps, baro, mag (estimate_*, nees_*:
            its error against the truth)``; sensors without an estimator: the truth, sensors logged.
        """
        meta = next(iter(self.results.values())).meta
        sensors = ", ".join(meta.get("sensor_models") or {})
        if not sensors:
            return ""
        estimator = (meta.get("estimator") or {}).get("kind")
        if estimator is None:
            return f"controllers flew on the true state (sensors {sensors} logged, no estimator)"
        return (
            f"controllers flew on the estimate: {estimator} on {sensors} "
            "(estimate_*, nees_*: its error against the truth, not the controllers')"
        )

    def plot(self, vehicle: int = 0, *, title: str | None = None):
        """Overlay of the flights: top view, x, y, z and the position error against time.

        :func:`quadcruise.plots.plot_paths` with a z panel.

        Parameters
        ----------
        vehicle : int
            Which vehicle of each flight to draw.
        title : str, optional
            Figure title; by default the labels joined by " vs " and the mission's kind.

        Returns
        -------
        matplotlib.figure.Figure
            Five axes: the top view, x, y and z [m] and the position error [m] (log
            scale) against time [s], with the environment's events and each flight's
            saturation marked.
        """
        from quadcruise.plots.flight import plot_paths

        return plot_paths(self.results, vehicle=vehicle, title=title, axes="xyz")

    def to_dict(self, **metric_kw: Any) -> dict:
        """Mission, vehicle, controllers and metrics as plain values (NaN as None), for JSON.

        Parameters
        ----------
        **metric_kw : Any
            Keywords of :meth:`metrics`.

        Returns
        -------
        dict
            ``workflow`` (``"compare"``), ``mission``, ``vehicle``, ``duration_s``, ``dt_s``,
            ``version`` (as the first flight recorded them), ``controllers`` (label ->
            parameters), ``metrics`` (label, or ``label/vehicle`` for a batch -> the row
            of :meth:`metrics`) and ``metrics_conventions`` (the table's conventions).
        """
        first = next(iter(self.results.values()))
        table = self.metrics(**metric_kw)
        rows = self._rows(table)
        return {
            "workflow": "compare",
            "mission": self.mission.to_dict(),
            "vehicle": first.meta.get("vehicle"),
            "duration_s": first.meta.get("duration_s"),
            "dt_s": first.meta.get("dt_s"),
            "version": first.meta.get("version"),
            "controllers": {label: controller_record(c) for label, c in self.controllers.items()},
            "metrics": rows,
            "metrics_conventions": plain(table.attrs.get("conventions")),
            **({"flown_on": self.flown_on()} if self.flown_on() else {}),
            **({"population": plain(self.population)} if self.population else {}),
        }

    def scenario_toml(self) -> str:
        """The comparison as a scenario file that ``quadcruise compare`` reads back.

        Returns
        -------
        str
            TOML: mission, vehicle, world and simulation of the flights, each controller with
            its label and gains under ``[[compare.controllers]]``, and the population flown
            (``[compare] population``).
        """
        from quadcruise.io.scenario_file import comparison_document, scenario_text, ulog_note

        first = next(iter(self.results.values()))
        records = {label: controller_record(c) for label, c in self.controllers.items()}
        doc = comparison_document(first.meta, records)
        if self.population:
            doc["compare"]["population"] = plain(self.population)
        header = "written by quadcruise from a comparison; `quadcruise compare THIS_FILE` flies it again"
        return scenario_text(doc, header=header + ulog_note(first.meta, "compare"))

    @staticmethod
    def _rows(table) -> dict:
        metrics = table.reset_index()
        by_vehicle = "vehicle" in metrics.columns
        rows: dict = {}
        for rec in metrics.to_dict(orient="records"):
            label = f"{rec.pop('controller')}/{rec['vehicle']}" if by_vehicle else rec.pop("controller")
            rows[label] = {k: plain(v) for k, v in rec.items()}
        return rows

    def write(self, out: str | os.PathLike, *, force: bool = False, **metric_kw: Any) -> Path:
        """Write ``metrics.csv``, ``comparison.png``, ``quadcruise.json`` (``to_dict``),
        ``scenario.toml`` and, with a population, ``population.csv`` into the folder ``out``,
        whole or not at all.

        Parameters
        ----------
        out : str or os.PathLike
            The output folder.
        force : bool
            Replace a non-empty folder that quadcruise did not write (else InputError).
        **metric_kw : Any
            Keywords of :meth:`metrics` (the conventions of the metrics written).

        Returns
        -------
        pathlib.Path
            The folder written.
        """
        from quadcruise.io.files import MARKER, atomic_dir, check_output_dir
        from quadcruise.plots.flight import save_figure

        scenarios = [r.meta.get("scenario", {}).get("source") for r in self.results.values()]
        out = check_output_dir(out, force, inputs=scenarios)
        with atomic_dir(out) as tmp:
            tmp = Path(tmp)
            self.metrics(**metric_kw).reset_index().to_csv(tmp / "metrics.csv", index=False)
            save_figure(self.plot(), tmp / "comparison.png")
            (tmp / MARKER).write_text(dumps(self.to_dict(**metric_kw), indent=2, sort_keys=True) + "\n")
            (tmp / "scenario.toml").write_text(self.scenario_toml())
            if self.population_table is not None:
                self.population_table.rename_axis("controller").to_csv(tmp / "population.csv")
        return out


def compare(
    mission: Mission | str = "circle",
    controllers: Sequence[Controller | str] | Mapping[str, Controller | str] | None = None,
    *,
    vehicle=None,
    duration: float | None = None,
    dt: float = 1e-3,
    progress: Callable[[int, int], None] | None = None,
    **fly_kw: Any,
) -> Comparison:
    """Fly ``mission`` with each controller on the same vehicle; see :class:`Comparison`.

    Parameters
    ----------
    mission : Mission or str
        A mission, or its name ('hover', 'step', 'circle', 'square') for the defaults.
    controllers : sequence or mapping, optional
        Names or Controller objects, labelled by their name (a repeated name gets '#2',
        '#3', ...), or a mapping label -> name or Controller; by default every controller
        declared ``compared=True`` (:func:`quadcruise.control.registry.compared_names`).
    vehicle : Vehicle, optional
        Table I by default.
    duration : float, optional
        Flight time [s]; the mission's default (one lap, step time + 10 s, ...) otherwise.
    dt : float
        Control period [s].
    progress : callable, optional
        ``progress(done, total)``: called with 0 before the first flight and after each
        controller's flight, with the number flown and the number of controllers.
    **fly_kw
        Any other keyword of :func:`quadcruise.fly` (``max_step``, ``log_every``, ``x0``, ...);
        with ``sensors`` (:class:`~quadcruise.estimation.Sensors`) and ``estimator``
        (:class:`~quadcruise.estimation.Ekf`) every controller flies on the estimate, the same
        sensor draws for each (one seed), and the table says so (:meth:`Comparison.flown_on`).

    Returns
    -------
    Comparison
        ``.results``, ``.metrics()``, ``.text()``, ``.plot()``, ``.to_dict()``, ``.write(out)``.
    """
    for bad in ("missions", "controller", "mission"):
        if bad in fly_kw:
            raise InputError(f"compare() flies one mission with each controller; '{bad}' is not an option")
    reject_unknown(
        "compare()",
        {k: v for k, v in fly_kw.items() if k not in FLY_OPTIONS},
        ["controllers", "progress", *(k for k in FLY_OPTIONS if k != "missions")],
    )
    w = "compare()"  # its own arguments checked before any flight
    mission = as_mission(mission, w)
    vehicle = checks.instance(w, "vehicle", as_vehicle(vehicle), (Vehicle, RotorVehicle))  # a preset's name too
    checks.number(w, "duration", duration, "pos", unit="s", optional=True)
    checks.number(w, "dt", dt, "pos", unit="s")
    checks.callback(w, "progress", progress)
    g = 9.81 if vehicle is None else vehicle_gravity(vehicle)  # sensors and estimator checked before any flight
    onboard_inputs(
        fly_kw.get("sensors"), fly_kw.get("estimator"), g=g, n=1, dt=float(dt), seed=0, first_vehicle=0, where=w
    )
    plant = plants.named("paper") if vehicle is None else plants.of(vehicle)
    plant.refuse_sensors(f"{w} argument sensors", fly_kw.get("sensors"))
    if controllers is None:
        controllers = compared_names()
    chosen = labelled(controllers)
    if vehicle is not None and plants.of(vehicle).designs_gains:  # a controller named: designed, as fly does
        believed = fly_kw.get("controller_vehicle")
        chosen = {
            label: flight_setup(vehicle, believed, ctrl.name)[1] if named else ctrl
            for (label, ctrl), named in zip(chosen.items(), named_entries(controllers), strict=True)
        }
    results = {}
    for label, ctrl in chosen.items():
        if progress is not None:
            progress(len(results), len(chosen))
        with flight_warnings_named(label):
            results[label] = fly(mission, ctrl, vehicle=vehicle, duration=duration, dt=dt, **fly_kw)
    if progress is not None:
        progress(len(results), len(chosen))
    return Comparison(mission=mission, controllers=chosen, results=results)


def named_entries(controllers) -> list[bool]:
    """Which of the controllers :func:`labelled` reads were given by name (in its order).

    Parameters
    ----------
    controllers : str, sequence or mapping
        As :func:`labelled` takes them.

    Returns
    -------
    list of bool
        True for an entry given as a name (a rotor-plant vehicle gives it designed gains).

    Examples
    --------
    >>> from quadcruise.control import SE3
    >>> named_entries("nlpd, se3"), named_entries(["nlpd", SE3()])
    ([True, True], [True, False])
    """
    if isinstance(controllers, str):
        return [True] * len(controllers.split(","))
    entries = controllers.values() if isinstance(controllers, Mapping) else controllers
    return [isinstance(c, str) for c in entries]


def labelled(controllers) -> dict:
    """Label -> controller, in the order given, as :func:`compare` flies them (a repeated name gets '#2', ...).

    Examples
    --------
    >>> list(labelled("nlpd, nlpd, se3"))
    ['nlpd', 'nlpd#2', 'se3']
    """
    if isinstance(controllers, str):
        text, controllers = controllers, [c.strip() for c in controllers.split(",")]
        if any(not c for c in controllers):
            raise InputError(f"controllers {text!r}: an empty name; give comma-separated names such as nlpd,se3")
    if not isinstance(controllers, (Mapping, list, tuple)):
        checks.fail(
            "compare()",
            "controllers",
            controllers,
            "comma-separated names, a list of controllers (names or objects) or a mapping label -> controller",
        )
    items = list(controllers.items()) if isinstance(controllers, Mapping) else [(None, c) for c in controllers]
    if not items:
        raise InputError("compare() needs at least one controller")
    out: dict = {}
    for label, c in items:
        ctrl = as_controller(c, "compare()")
        name = str(label) if label is not None else ctrl.name
        k, unique = 1, name
        while unique in out:
            k += 1
            unique = f"{name}#{k}"
        out[unique] = ctrl
    return out
