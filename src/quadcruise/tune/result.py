"""The result of a tune: the gains found, the metrics they reach against the targets, the
history of the search, and the folder that holds it all, with a ``scenario.toml`` that
``quadcruise fly`` flies with the tuned gains."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from quadcruise._version import __version__
from quadcruise.io.files import MARKER, atomic_dir, check_output_dir
from quadcruise.io.plainjson import dumps
from quadcruise.metrics.summary import Summary
from quadcruise.montecarlo.population import SPREADS
from quadcruise.montecarlo.schema import METRICS

__all__ = ["TuneResult"]


def _num(value: Any) -> float | None:
    value = float(value)
    return value if math.isfinite(value) else None


def _fmt(value: Any, spec: str = ".4g") -> str:
    return "-" if value is None or not math.isfinite(float(value)) else format(float(value), spec)


@dataclass
class TuneResult:
    """A finished tune. :func:`quadcruise.tune.tune` builds it.

    Parameters
    ----------
    controller : Controller
        The tuned controller (the base controller with the gains found).
    start : Controller
        The controller the search started from.
    gains : dict of str to float
        The gains found, by name.
    start_gains : dict of str to float
        The same gains of the starting controller.
    bounds : dict of str to (float, float, str)
        Each gain's bounds and scale ("log" or "linear").
    targets, requirements : tuple
        :class:`~quadcruise.tune.criteria.Target` and
        :class:`~quadcruise.montecarlo.requirements.Requirement`.
    minimize : tuple of str
        The minimised metrics.
    statistic : str or float
        ``"worst"`` or the quantile of a candidate's flights that the cost took.
    cost : float
        The tuned gains' cost.
    flights : pandas.DataFrame
        The tuned gains' M flights: one row each, the metrics and ``cost`` (what :meth:`metrics`
        and :meth:`to_pandas` copy).
    history : pandas.DataFrame
        Every candidate flown, one row per candidate (a candidate is M flights):
        ``generation`` (0: the first), ``candidate``, the gains, ``cost``.
    response, start_response : SimResult
        The tuned and the starting gains on the nominal vehicle (the population's
        environment and sensor noise, no spread), flown as the search flew them: logged
        every ``spec.log_every`` periods (the log the metrics were measured on) and judged
        by the spec's bounds, so that the folder's scenario.toml, flown again, gives the
        tuned metrics.
    spec : MonteCarloSpec
        Mission, nominal vehicle, population, seed, flight time and step.
    info : dict
        ``samples``, ``popsize``, ``budget``, ``generations``, ``flights``, ``wall_s``,
        ``command``.
    """

    controller: Any
    start: Any
    gains: dict
    start_gains: dict
    bounds: dict
    targets: tuple
    requirements: tuple
    minimize: tuple
    statistic: Any
    cost: float
    flights: Any
    history: Any
    response: Any
    start_response: Any
    spec: Any
    info: dict = field(default_factory=dict)

    @classmethod
    def from_search(cls, obj, *, budget: int, popsize: int, command: str = "") -> TuneResult:
        """The result of a search from its objective, which kept every generation flown.

        Parameters
        ----------
        obj : Objective
            The search's objective, after the search.
        budget : int
            The generations allowed.
        popsize : int
            Candidates per generation.
        command : str
            The command line, for the record.

        Returns
        -------
        TuneResult
            With the best candidate of all generations (the first of equals).
        """
        import pandas as pd

        from quadcruise.workflows.fly import fly

        evs = obj.evaluations
        k_gen = int(np.argmin([e.cost.min() for e in evs]))
        ev = evs[k_gen]
        k = int(np.argmin(ev.cost))
        controller = obj.space.controllers(ev.values[k : k + 1])[0]
        rows = []
        for g, e in enumerate(evs):
            for i in range(e.values.shape[0]):
                rows.append(
                    {
                        "generation": g,
                        "candidate": i,
                        **dict(zip(obj.space.names, e.values[i], strict=False)),
                        "cost": float(e.cost[i]),
                    }
                )
        flights = pd.DataFrame(
            {
                "sample": np.arange(obj.samples),
                **{m: ev.metrics[m][k] for m in METRICS},
                "status": ev.metrics["status"][k],
                "cost": ev.flight_cost[k],
            }
        )
        spec = obj.spec
        kw = dict(
            vehicle=spec.vehicle,
            controller_vehicle=spec.controller_vehicle,
            duration=spec.duration,
            dt=spec.dt,
            seed=spec.seed,
            environment=spec.population.environment,
            sensors=spec.population.noise if spec.population.sensors is None else spec.population.sensors,
            estimator=spec.population.estimator,  # the estimator the search flew on, flown again
            log_every=spec.log_every,  # the search's log and bounds: its metrics, flown again
            max_steady_error=spec.max_track_error_m,
            max_altitude_error=spec.max_altitude_error_m,
        )
        import warnings

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            response = fly(spec.mission, controller, **kw)
            start_response = fly(spec.mission, obj.space.base, **kw)
        info = {
            "samples": obj.samples,
            "popsize": popsize,
            "budget": budget,
            "generations": len(evs) - 1,
            "flights": int(sum(e.values.shape[0] for e in evs) * obj.samples),
            "wall_s": float(sum(e.wall_s for e in evs)),
            "command": command,
        }
        return cls(
            controller=controller,
            start=obj.space.base,
            gains=obj.space.describe(controller),
            start_gains=obj.space.describe(obj.space.base),
            bounds={g.name: (g.low, g.high, "log" if g.log else "linear") for g in obj.space.gains},
            targets=obj.targets,
            requirements=obj.requirements,
            minimize=obj.minimize,
            statistic=obj.statistic,
            cost=float(ev.cost[k]),
            flights=flights,
            history=pd.DataFrame(rows),
            response=response,
            start_response=start_response,
            spec=spec,
            info=info,
        )

    # --- what was reached --------------------------------------------------------------
    @property
    def generations(self) -> int:
        """Generations flown after the first."""
        return int(self.info["generations"])

    def reached(self, metric: str) -> float | None:
        """A metric of the tuned gains, by the objective's statistic over the M flights
        (the worst: the largest value).

        Parameters
        ----------
        metric : str
            A metric of :data:`~quadcruise.montecarlo.schema.METRICS`.

        Returns
        -------
        float or None
            None where it has no value (a flight that failed or never settled).
        """
        values = self.flights[metric].to_numpy(dtype=float)
        if self.statistic == "worst" or values.size == 1:
            value = values.max()
        else:
            value = np.quantile(values, float(self.statistic), method="higher")
        return _num(value)

    @property
    def met(self) -> bool:
        """True if every target and every requirement is met (by the objective's statistic)."""
        return all(r["met"] for r in self._checks())

    def _checks(self) -> list[dict]:
        out = []
        for t in self.targets:
            value = self.reached(t.metric)
            out.append(
                {
                    "kind": "target",
                    "metric": t.metric,
                    "text": f"{t.value:g} +- {t.tolerance:g}",
                    "target": t.value,
                    "tolerance": t.tolerance,
                    "reached": value,
                    "met": value is not None and bool(t.met(value)),
                }
            )
        for r in self.requirements:
            value = self.reached(r.metric)
            out.append(
                {
                    "kind": "requirement",
                    "metric": r.metric,
                    "text": f"{r.op} {r.value:g}",
                    "bound": r.value,
                    "op": r.op,
                    "reached": value,
                    "met": value is not None and bool(r.met(value)),
                }
            )
        for m in self.minimize:
            out.append({"kind": "minimize", "metric": m, "text": "minimize", "reached": self.reached(m), "met": True})
        return out

    # --- ResultLike ----------------------------------------------------------------------
    def metrics(self):
        """The metrics of the tuned gains' M flights, one row per flight (:attr:`flights`).

        Returns
        -------
        pandas.DataFrame
            A copy of :attr:`flights`: the metrics and ``cost``. Every candidate flown (one
            row per candidate, not per flight) is :attr:`history`.
        """
        return self.flights.copy()

    def to_pandas(self):
        """The tuned gains' flights, one row each: :meth:`metrics`.

        Returns
        -------
        pandas.DataFrame
            :meth:`metrics`.
        """
        return self.metrics()

    def summary(self) -> Summary:
        """The gains found and the metrics they reach against the targets.

        Returns
        -------
        Summary
            ``controller``, ``mission``, ``gains`` (name -> start, tuned, bounds),
            ``checks`` (each target, requirement and minimised metric: reached, met), ``met``,
            ``cost``, ``objective``, ``seed`` and the run's ``info``.
        """
        data = {
            "controller": self.controller.name,
            "mission": self.spec.mission.name,
            "gains": {
                n: {
                    "start": self.start_gains[n],
                    "tuned": v,
                    "low": self.bounds[n][0],
                    "high": self.bounds[n][1],
                    "scale": self.bounds[n][2],
                }
                for n, v in self.gains.items()
            },
            "checks": self._checks(),
            "met": self.met,
            "cost": self.cost,
            "objective": self.statistic if self.statistic == "worst" else f"quantile {self.statistic:g}",
            "seed": self.spec.seed,
            "info": dict(self.info),
        }
        return Summary(data, self.summary_text(data))

    def summary_text(self, data: dict | None = None) -> str:
        """The summary as a table for a terminal.

        Parameters
        ----------
        data : dict, optional
            :meth:`summary`'s numbers (computed if not given).

        Returns
        -------
        str
        """
        data = data or self.summary().to_dict()
        info = data["info"]
        over = f"; the {data['objective']} of {info['samples']} vehicles" if info["samples"] > 1 else ""
        lines = [
            f"tuned {data['controller']} on {data['mission']}: {info['generations']} generations, "
            f"{info['flights']:,} flights in {info['wall_s']:.1f} s (seed {data['seed']}){over}",
            f"{'gain':<22}{'start':>10}{'tuned':>12}  bounds",
        ]
        for name, g in data["gains"].items():
            lines.append(
                f"{name:<22}{_fmt(g['start']):>10}{_fmt(g['tuned'], '.5g'):>12}  "
                f"[{g['low']:.4g}, {g['high']:.4g}] {g['scale']}"
            )
        lines.append(f"{'metric':<22}{'wanted':>16}{'reached':>10}  met")
        for c in data["checks"]:
            lines.append(
                f"{c['metric']:<22}{c['text']:>16}{_fmt(c['reached']):>10}  "
                f"{'-' if c['kind'] == 'minimize' else ('yes' if c['met'] else 'NO')}"
            )
        lines.append(
            f"cost {data['cost']:.4g}; "
            + ("every target and requirement met" if data["met"] else "not every target or requirement met")
        )
        return "\n".join(lines)

    def plot(self):
        """Convergence, and the tuned response against the targets (:func:`quadcruise.plots.tune.plot_tune`).

        Returns
        -------
        matplotlib.figure.Figure
        """
        from quadcruise.plots.tune import plot_tune

        gains = ", ".join(f"{n} {v:.4g}" for n, v in self.gains.items())
        return plot_tune(self, title=f"{self.controller.name} on {self.spec.mission.name}: {gains}")

    def scenario_toml(self) -> str:
        """The tuned gains as a scenario that ``quadcruise fly`` flies (and, with a population,
        whose ``[montecarlo]`` table ``quadcruise montecarlo --scenario`` reads).

        Returns
        -------
        str
            TOML, with the command that tuned it in its header.
        """
        from quadcruise.io.scenario_file import scenario_document, scenario_text

        doc = scenario_document(self.response.meta, title=f"{self.controller.name} tuned on {self.spec.mission.name}")
        pop = self.spec.population
        spread_names = (*SPREADS, "offset", "wind_spread", "imu_noise_spread", "gps_noise_spread")
        spreads = {k: getattr(pop, k) for k in spread_names if getattr(pop, k)}
        if spreads or self.info["samples"] > 1:
            doc["montecarlo"] = {
                **spreads,
                "distribution": pop.distribution,
                "model_error": pop.model_error,
                "n": self.info["samples"],
                "seed": self.spec.seed,
            }
        wanted = ", ".join(
            [t.text for t in self.targets]
            + [r.text for r in self.requirements]
            + [f"minimize {m}" for m in self.minimize]
        )
        header = (
            f"tuned by quadcruise {__version__} for {wanted}\n"
            + (f"regenerate: {self.info['command']}\n" if self.info.get("command") else "")
            + "`quadcruise fly THIS_FILE` flies the tuned gains"
        )
        return scenario_text(doc, header=header)

    def to_json(self) -> dict:
        """``tune.json``: the summary's numbers and the history's best per generation.

        Returns
        -------
        dict
        """
        best = self.history.groupby("generation")["cost"].min().cummin()
        data = self.summary().to_dict()
        data["best_cost_by_generation"] = [float(c) for c in best]
        data["version"] = __version__
        return data

    def write(self, out: str | Path, *, force: bool = False) -> Path:
        """Write the tune's folder, whole or not at all: ``scenario.toml`` (the tuned gains,
        which ``quadcruise fly`` flies), ``tune.json`` (gains, targets, what was reached),
        ``history.csv`` (every candidate), ``flights.csv`` (the tuned gains' M flights),
        ``tune.png`` (:meth:`plot`) and ``quadcruise.json``.

        Parameters
        ----------
        out : str or pathlib.Path
            The folder.
        force : bool
            Replace a non-empty folder that quadcruise did not write.

        Returns
        -------
        pathlib.Path
        """
        from quadcruise.plots.flight import save_figure

        out = check_output_dir(out, force)
        with atomic_dir(out) as tmp:
            tmp = Path(tmp)
            (tmp / "scenario.toml").write_text(self.scenario_toml())
            (tmp / "tune.json").write_text(dumps(self.to_json(), indent=2) + "\n")
            self.history.to_csv(tmp / "history.csv", index=False)
            self.flights.to_csv(tmp / "flights.csv", index=False)
            save_figure(self.plot(), tmp / "tune.png")
            (tmp / MARKER).write_text(
                dumps(
                    {
                        "workflow": "tune",
                        "version": __version__,
                        "command": self.info.get("command", ""),
                        "spec": self.spec.to_dict() if hasattr(self.spec, "to_dict") else {},
                    },
                    indent=2,
                )
                + "\n"
            )
        return out
