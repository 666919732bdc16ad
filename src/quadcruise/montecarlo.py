"""Monte Carlo sweeps: a population of perturbed vehicles flown through the batched engine,
with the distribution of every metric, the failure rate and its reasons, the worst cases
(each replayable alone), histograms and an envelope of the paths.

The pieces, from the bottom up:

- :class:`Population`: relative spreads of the vehicle's parameters, an initial position
  offset, a random steady wind, an :class:`~quadcruise.disturbances.Environment` and
  :class:`~quadcruise.disturbances.SensorNoise`;
- :class:`MonteCarloSpec`: the population with the mission, controller, nominal vehicle,
  seed, flight time and step: everything that fixes the flights (it has a :meth:`hash`);
- :func:`quadcruise.sweep.run_chunk`: vehicles ``first .. first + count - 1`` flown as one batch, reduced to
  one row of metrics each plus a few decimated paths. It is a pure function of
  ``(spec, first, count)``, and vehicle i's flight depends on ``(seed, i)`` only, so any
  split into chunks gives the same table;
- :func:`montecarlo`: the whole population, in process or on Dask, streamed to disk and
  resumable (see :mod:`quadcruise.sweep`), returning a :class:`MonteCarloResult`;
- :func:`montecarlo_case` / :func:`replay_case`: one vehicle flown alone again.

Randomness. Vehicle i's drawn parameters come only from
``numpy.random.SeedSequence([seed, i], spawn_key=(1,))`` (16 unit draws, always all of
them, in a fixed order, so changing one spread never moves another's draws); its sensor
noise and turbulence come from the engine's stream of ``(seed, i)``
(:mod:`quadcruise.rng`).

Metrics are computed on a log at ``log_dt`` (10 ms by default, not every control period):
this bounds memory (a 60 s flight logs 6,001 instants instead of 60,001) at the cost of
sampling: a maximum taken over 10 ms samples, crossings interpolated between them, the
RMSE integrated by trapezoids 10 ms wide. Against a full-rate (1 ms) log the times differ
by less than 0.1 ms and the errors by less than 2e-5 relative, except an RMSE across a
jump of the reference (the step mission), where the trapezoid straddling the jump is
10 ms wide instead of 1 ms: 0.24 % there (measured on 20 perturbed vehicles).

Examples
--------
>>> from quadcruise.montecarlo import Population, montecarlo
>>> res = montecarlo("hover", "nlpd", Population(mass_spread=0.05, offset=0.1), n=4, seed=1,
...                  duration=0.5, scheduler="none")
>>> len(res.table), res.table["vehicle"].tolist()
(4, [0, 1, 2, 3])
>>> res.summary()["failures"]["count"]             # 0.5 s is too short to settle
4
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

from . import __version__
from .control import Controller, controller_from_name
from .errors import InputError
from .io import check_output_dir
from .missions import Mission, mission_from_name
from .params import Vehicle

__all__ = ["Population", "MonteCarloSpec", "MonteCarloResult", "Traces", "Case", "montecarlo",
           "montecarlo_case", "replay_case", "montecarlo_command", "parse_noise", "FAILURES",
           "COLUMNS", "METRICS"]

DRAW_KEY = 1
"""spawn_key of the population's draws (the engine's own streams have none)."""
N_DRAWS = 16
SLOTS = {"m": 0, "Jxx": 1, "Jyy": 2, "Jzz": 3, "K": 4, "omega": 5, "d": 6,
         "dx0": 7, "dy0": 8, "dz0": 9, "wind_x": 10, "wind_y": 11}
"""Which of the 16 unit draws of a vehicle feeds which quantity (12..15 are spare)."""
SPREADS = {"mass_spread": ("m",), "inertia_spread": ("Jxx", "Jyy", "Jzz"), "thrust_spread": ("K",),
           "bandwidth_spread": ("omega",), "yaw_arm_spread": ("d",)}
CLIP = {"normal": 3.0, "uniform": math.sqrt(3.0)}
"""Largest |unit draw|: normal draws are clipped at 3 sigma, uniform ones span +-sqrt(3)
(unit standard deviation)."""

FAILURES = ("ok", "diverged", "saturated", "did not settle")
"""Failure codes 0..3 of the table's ``failure`` column, in order of precedence."""
METRICS = ("rmse_m", "max_error_m", "final_error_m", "rise_time_s", "settling_time_s",
           "settling_time_5pct_s", "overshoot_pct", "effort", "duty_clipped_s", "controller_limited_s")
"""The metrics summarised by quantiles (NaN where not applicable is left out)."""
COLUMNS = {
    "vehicle": np.int64, "status": np.int64, "stop_time_s": float, "failure": np.int64,
    "diverged": bool, "saturated": bool, "not_settled": bool, "transient_axis": np.int64,
    **{m: float for m in METRICS},
    **{k: float for k in SLOTS},
}
"""Columns of the per-flight table and their types: engine ``status`` (see
:data:`quadcruise.result.STATUS_REASONS`), ``failure`` (see :data:`FAILURES`),
``transient_axis`` (0, 1, 2 for x, y, z; -1 if none), the metrics and the drawn values
(``dx0``..: initial offset [m]; ``wind_x``, ``wind_y``: steady wind [m/s])."""


# --- population -------------------------------------------------------------------------
@dataclass(frozen=True)
class Population:
    """How the vehicles of a sweep differ from the nominal one.

    Attributes
    ----------
    mass_spread, inertia_spread, thrust_spread, bandwidth_spread, yaw_arm_spread : float
        Relative standard deviations of m; of Jxx, Jyy, Jzz (each drawn on its own); of the
        thrust gain K; of the rotor bandwidth omega; of the yaw moment arm d. A value is
        ``nominal * (1 + spread * z)`` with z a unit draw: normal clipped to [-3, 3], or
        uniform on [-sqrt 3, sqrt 3]. So that every value stays positive a spread must be
        < 1/3 (normal) or < 1/sqrt 3 (uniform).
    offset : float
        Standard deviation [m] of the initial position offset on each axis (same clipping).
    wind_spread : float
        Standard deviation [m/s] of a steady horizontal wind on x and on y, drawn per vehicle
        and added to the environment's steady wind.
    distribution : {"normal", "uniform"}
    environment : Environment, optional
        Wind, gust, turbulence, rotor loss, the same for every vehicle (turbulence differs by
        vehicle through its random stream). Wind acts through drag: a vehicle without drag
        gets :data:`~quadcruise.disturbances.DEFAULT_DRAG` (with a warning).
    noise : SensorNoise, optional
    model_error : bool
        The controller computes with the nominal vehicle (True) or knows each vehicle's
        drawn parameters (False).

    Examples
    --------
    >>> p = Population(mass_spread=0.1)
    >>> d = p.draw(seed=1, first=0, count=5, nominal=Vehicle.paper())
    >>> d.vehicle.batch_size, bool(np.all(p.draw(1, 3, 2, Vehicle.paper()).vehicle.m == d.vehicle.m[3:]))
    (5, True)
    >>> Population(mass_spread=-0.1)
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: population field 'mass_spread' must be a number >= 0, got -0.1
    """

    mass_spread: float = 0.0
    inertia_spread: float = 0.0
    thrust_spread: float = 0.0
    bandwidth_spread: float = 0.0
    yaw_arm_spread: float = 0.0
    offset: float = 0.0
    wind_spread: float = 0.0
    distribution: str = "normal"
    environment: Any = None
    noise: Any = None
    model_error: bool = True

    def __post_init__(self) -> None:
        if self.distribution not in CLIP:
            raise InputError(f"population field 'distribution' must be normal or uniform, got {self.distribution!r}")
        for name in (*SPREADS, "offset", "wind_spread"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
                    or not math.isfinite(value) or value < 0:
                raise InputError(f"population field '{name}' must be a number >= 0, got {value!r}")
            object.__setattr__(self, name, float(value))
            limit = 1.0 / CLIP[self.distribution]
            if name in SPREADS and value >= limit:
                raise InputError(f"population field '{name}' = {value:g} is too large: with {self.distribution} "
                                 f"draws it must be < {limit:.4f} so that every value stays positive")
        from .disturbances import Environment, SensorNoise

        if self.environment is not None:
            if not isinstance(self.environment, Environment):
                raise InputError("population field 'environment' must be an Environment or None")
            if self.environment.batch_size is not None:
                raise InputError("the population's environment must be the same for every vehicle "
                                 "(per-vehicle values come from the spreads)")
        if self.noise is not None:
            if not isinstance(self.noise, SensorNoise):
                raise InputError("population field 'noise' must be a SensorNoise or None")
            if np.ndim(self.noise.std_vector()) > 1:
                raise InputError("the population's sensor noise must be the same for every vehicle")
        object.__setattr__(self, "model_error", bool(self.model_error))

    @property
    def needs_drag(self) -> bool:
        """True if the vehicles meet wind (which acts only through drag)."""
        return self.wind_spread > 0 or (self.environment is not None and self.environment.needs_drag)

    def unit_draws(self, seed: int, first: int, count: int) -> np.ndarray:
        """(count, 16) unit draws of vehicles first .. first + count - 1 (see the module)."""
        out = np.empty((count, N_DRAWS))
        normal = self.distribution == "normal"
        for k in range(count):
            g = np.random.default_rng(np.random.SeedSequence([seed, first + k], spawn_key=(DRAW_KEY,)))
            out[k] = g.standard_normal(N_DRAWS) if normal else g.random(N_DRAWS)
        return np.clip(out, -3.0, 3.0) if normal else math.sqrt(3.0) * (2.0 * out - 1.0)

    def draw(self, seed: int, first: int, count: int, nominal: Vehicle, dt: float = 1e-3) -> "Draw":
        """The vehicles first .. first + count - 1: parameters, offsets and environment."""
        if nominal.batch_size is not None:
            raise InputError("the nominal vehicle of a population must not be batched")
        z = self.unit_draws(seed, first, count)
        cols: dict[str, np.ndarray] = {}
        for spread, names in SPREADS.items():
            for name in names:
                cols[name] = getattr(nominal, name) * (1.0 + getattr(self, spread) * z[:, SLOTS[name]])
        offsets = self.offset * z[:, [SLOTS["dx0"], SLOTS["dy0"], SLOTS["dz0"]]]
        cols.update(dx0=offsets[:, 0], dy0=offsets[:, 1], dz0=offsets[:, 2])
        env = self.environment
        base = (0.0, 0.0, 0.0) if env is None or env.wind is None else tuple(map(float, env.wind.velocity))
        wind = np.column_stack([base[0] + self.wind_spread * z[:, SLOTS["wind_x"]],
                                base[1] + self.wind_spread * z[:, SLOTS["wind_y"]],
                                np.full(count, base[2])])
        cols.update(wind_x=wind[:, 0], wind_y=wind[:, 1])
        kwargs: dict[str, Any] = {}
        if self.wind_spread > 0:
            from .disturbances import ConstantWind, Environment

            env = dataclasses.replace(env or Environment(), wind=ConstantWind(velocity=wind))
        if env is not None and env.parts:
            kwargs.update(env.kwargs(count))
        if self.noise is not None:
            kwargs.update(self.noise.kwargs(dt))
        vehicle = nominal.replace(**{k: cols[k] for k in ("m", "Jxx", "Jyy", "Jzz", "K", "omega", "d")})
        return Draw(vehicle=vehicle, offsets=offsets, environment=kwargs, columns=cols)

    def to_dict(self) -> dict:
        """Plain values, for the result folder."""
        out = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        for key in ("environment", "noise"):
            out[key] = None if out[key] is None else out[key].to_dict()
        return out


@dataclass(frozen=True)
class Draw:
    """A chunk's drawn vehicles (batched), initial offsets [m], ``fly`` environment keywords
    and the drawn values as table columns."""

    vehicle: Vehicle
    offsets: np.ndarray
    environment: dict
    columns: dict


# --- the spec ---------------------------------------------------------------------------
def _divisor_at_most(n: int, target: int) -> int:
    """The largest divisor of n that is <= target (>= 1)."""
    for k in range(max(1, min(n, target)), 0, -1):
        if n % k == 0:
            return k
    return 1


@dataclass(frozen=True)
class MonteCarloSpec:
    """Everything that fixes the flights of a sweep (not how many, nor where they run).

    Attributes
    ----------
    mission, controller : Mission / Controller or their names
    population : Population
    seed : int
        Vehicle i depends on (seed, i) only.
    duration : float, optional
        Flight time [s]; the mission's default (one lap, ...) if None.
    dt : float
        Control period [s].
    vehicle : Vehicle
        The nominal vehicle (Table I); given drag if the population meets wind.
    max_step : float, optional
        Longest RK4 substep [s]; dt by default.
    log_dt : float
        Sampling of the log the metrics are computed on [s] (rounded to a divisor of the
        flight's periods).
    trace_dt : float
        Sampling of the kept paths [s].
    max_traces : int
        Paths kept of the first this many vehicles (a random sample: the draws are i.i.d.).
    max_failure_traces : int
        Paths kept of the first this many failed vehicles.
    settle_band : float
        A measured transient that is outside this band (fraction of the initial error) at
        the end "did not settle".
    max_clipped_s : float
        Clipping of rotor duties for longer than this [s] counts as "saturated".
    transient_until : float, optional
        End of the window in which the transient is measured [s].
    full_dynamics : bool
        Exact Euler-angle kinematics.
    """

    mission: Any = "circle"
    controller: Any = "nlpd"
    population: Population = field(default_factory=Population)
    seed: int = 0
    duration: float | None = None
    dt: float = 1e-3
    vehicle: Vehicle = field(default_factory=Vehicle.paper)
    max_step: float | None = None
    log_dt: float = 0.01
    trace_dt: float = 0.1
    max_traces: int = 200
    max_failure_traces: int = 50
    settle_band: float = 0.05
    max_clipped_s: float = 0.0
    transient_until: float | None = None
    full_dynamics: bool = False

    def __post_init__(self) -> None:
        from .engine import time_grid
        from .flight import default_duration

        if isinstance(self.mission, str):
            object.__setattr__(self, "mission", mission_from_name(self.mission))
        if isinstance(self.controller, str):
            object.__setattr__(self, "controller", controller_from_name(self.controller))
        if not isinstance(self.mission, Mission):
            raise InputError(f"mission must be a name or a Mission, got {type(self.mission).__name__}")
        if not isinstance(self.controller, Controller):
            raise InputError(f"controller must be a name or a Controller, got {type(self.controller).__name__}")
        if not isinstance(self.population, Population):
            raise InputError("population must be a Population")
        if not isinstance(self.vehicle, Vehicle) or self.vehicle.batch_size is not None:
            raise InputError("the nominal vehicle must be one (unbatched) Vehicle")
        if isinstance(self.seed, bool) or not isinstance(self.seed, (int, np.integer)) or self.seed < 0:
            raise InputError(f"seed must be an integer >= 0, got {self.seed!r}")
        object.__setattr__(self, "seed", int(self.seed))
        duration = default_duration(self.mission) if self.duration is None else self.duration
        time_grid(float(duration), float(self.dt))          # validates duration and dt
        object.__setattr__(self, "duration", float(duration))
        object.__setattr__(self, "dt", float(self.dt))
        for name in ("log_dt", "trace_dt", "settle_band"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise InputError(f"{name} must be a positive number, got {value!r}")
        if not 0 < self.settle_band < 1:
            raise InputError(f"settle_band must be a fraction in (0, 1), got {self.settle_band!r}")
        if not (math.isfinite(self.max_clipped_s) and self.max_clipped_s >= 0):
            raise InputError(f"max_clipped_s must be >= 0, got {self.max_clipped_s!r}")
        for name in ("max_traces", "max_failure_traces"):
            if int(getattr(self, name)) != getattr(self, name) or getattr(self, name) < 0:
                raise InputError(f"{name} must be a whole number >= 0, got {getattr(self, name)!r}")
        if self.population.needs_drag:
            from .disturbances import with_drag

            object.__setattr__(self, "vehicle", with_drag(self.vehicle))

    # --- derived ------------------------------------------------------------------------
    @property
    def periods(self) -> int:
        """Control periods per flight."""
        return round(self.duration / self.dt)

    @property
    def log_every(self) -> int:
        """Control periods between logged instants (a divisor of the periods)."""
        return _divisor_at_most(self.periods, max(1, round(self.log_dt / self.dt)))

    @property
    def trace_every(self) -> int:
        """Logged instants between kept path samples."""
        n_log = self.periods // self.log_every
        return _divisor_at_most(n_log, max(1, round(self.trace_dt / (self.dt * self.log_every))))

    def log_bytes(self) -> int:
        """Bytes the engine's log takes per vehicle (states, commands, references)."""
        return (self.periods // self.log_every + 1) * (16 + 12 + 11) * 8

    def to_dict(self) -> dict:
        """Plain values (for quadcruise.json and the hash)."""
        out = {"mission": self.mission.to_dict(), "controller": self.controller.to_dict(),
               "population": self.population.to_dict(), "vehicle": self.vehicle.to_dict()}
        for f in dataclasses.fields(self):
            if f.name not in out:
                out[f.name] = getattr(self, f.name)
        out["log_every"], out["trace_every"] = self.log_every, self.trace_every
        return out

    def hash(self) -> str:
        """A short hash of :meth:`to_dict` and the version: equal specs fly equal flights."""
        text = json.dumps({"spec": self.to_dict(), "version": __version__}, sort_keys=True, default=_plain)
        return hashlib.sha256(text.encode()).hexdigest()[:16]


def _plain(obj):
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, np.generic):
        return obj.item()
    if dataclasses.is_dataclass(obj):
        return dataclasses.asdict(obj)
    raise TypeError(f"cannot record {type(obj).__name__}")


# --- results ----------------------------------------------------------------------------
@dataclass
class Traces:
    """The kept paths: vehicle indices (k,), times (L,), positions and references (k, L, 3),
    ``sample`` (k,): True for the random sample (the first vehicles), False for extra
    failures."""

    vehicle: np.ndarray
    t: np.ndarray
    pos: np.ndarray
    ref: np.ndarray
    sample: np.ndarray


@dataclass
class MonteCarloResult:
    """A finished sweep: one table row per flight, the kept paths, and how it ran.

    Attributes
    ----------
    spec : MonteCarloSpec
    table : pandas.DataFrame
        One row per flight, sorted by vehicle index (see :data:`COLUMNS`), plus ``reason``
        (the failure as text).
    traces : Traces
    info : dict
        Scheduler, workers, chunk size, chunks flown and resumed, wall time, output folder.
    """

    spec: MonteCarloSpec
    table: Any
    traces: Traces
    info: dict = field(default_factory=dict)

    @property
    def n(self) -> int:
        """Number of flights."""
        return len(self.table)

    def summary(self) -> dict:
        """Failure rate by reason (each flight counted once, under the first of diverged,
        saturated, did not settle), the engine's stop reasons, and p5/p50/p95/max/mean of
        each metric over the flights where it is defined (``count`` of them)."""
        from .result import STATUS_REASONS

        tab = self.table
        n = len(tab)
        failure = tab["failure"].to_numpy()
        by_reason = {FAILURES[c]: {"count": int(np.count_nonzero(failure == c)),
                                   "rate": float(np.count_nonzero(failure == c) / n)} for c in (1, 2, 3)}
        stops = {STATUS_REASONS[c]: int(k) for c, k in zip(*np.unique(tab["status"], return_counts=True)) if c}
        metrics = {}
        for name in METRICS:
            v = tab[name].to_numpy(dtype=float)
            v = v[np.isfinite(v)]
            q = np.percentile(v, [5, 50, 95]) if v.size else [np.nan] * 3
            metrics[name] = {"count": int(v.size), "p5": _num(q[0]), "p50": _num(q[1]), "p95": _num(q[2]),
                             "max": _num(v.max() if v.size else np.nan), "mean": _num(v.mean() if v.size else np.nan)}
        fails = int(np.count_nonzero(failure))
        return {"flights": n, "seed": self.spec.seed,
                "failures": {"count": fails, "rate": fails / n, "by_reason": by_reason},
                "stopped": stops, "metrics": metrics}

    def summary_text(self) -> str:
        """The summary as aligned text (for the terminal)."""
        s = self.summary()
        f = s["failures"]
        lines = [f"{s['flights']:,} flights of {self.spec.controller.name} on {self.spec.mission.name}, "
                 f"seed {s['seed']}: {f['count']:,} failed ({100 * f['rate']:.2f} %)"]
        for reason, v in f["by_reason"].items():
            lines.append(f"  {reason:<16} {v['count']:>8,}  ({100 * v['rate']:.2f} %)")
        lines.append(f"  {'metric':<22}{'count':>8}{'p5':>11}{'p50':>11}{'p95':>11}{'max':>11}")
        for name, m in s["metrics"].items():
            lines.append(f"  {name:<22}{m['count']:>8,}" + "".join(
                f"{'-' if m[k] is None else format(m[k], '.4g'):>11}" for k in ("p5", "p50", "p95", "max")))
        return "\n".join(lines)

    def worst(self, k: int = 10, by: str = "rmse_m"):
        """The k worst flights: failures first (diverged, earliest stop first; then saturated,
        then did not settle), then by ``by``, largest first. Each row has the ``vehicle``
        index and the ``seed``: :func:`replay_case` flies it again alone."""
        if by not in self.table.columns:
            raise InputError(f"unknown metric {by!r}; choose one of {', '.join(METRICS)}")
        tab = self.table
        rank = np.array([0, 3, 2, 1])[tab["failure"].to_numpy()]          # diverged first
        value = tab[by].to_numpy(dtype=float)
        stop = np.where(tab["failure"].to_numpy() == 1, tab["stop_time_s"].to_numpy(), 0.0)
        order = np.lexsort((tab["vehicle"].to_numpy(), np.nan_to_num(-value, nan=np.inf), stop, -rank))
        out = tab.iloc[order[:k]].copy()
        out.insert(1, "seed", self.spec.seed)
        return out.reset_index(drop=True)

    def case(self, i: int, **kw):
        """:func:`replay_case` of vehicle i."""
        return replay_case(self, i, **kw)

    def plot_histograms(self, metrics=("rmse_m", "max_error_m", "final_error_m", "rise_time_s",
                                       "settling_time_5pct_s", "overshoot_pct", "effort", "duty_clipped_s")):
        """Histograms of the metrics (finite values; lines at 5 %, median, 95 %) and a bar
        chart of the outcomes: a matplotlib Figure."""
        from .sweep import plot_histograms

        return plot_histograms(self, metrics)

    def plot_envelope(self):
        """Top view of the kept paths (the first vehicles; failures in orange, diverged in
        red, with their first extra failures) and the median and 5-95 % band of the
        position error of the first vehicles against time: a matplotlib Figure."""
        from .sweep import plot_envelope

        return plot_envelope(self)

    def write(self, out: str | Path, *, fmt: str = "csv", force: bool = False) -> Path:
        """Write flights.csv (or .parquet), summary.json, worst.csv, histograms.png,
        envelope.png, report.md and quadcruise.json into ``out``, each file whole or not at
        all. A folder holding the chunks of this same sweep is completed in place."""
        from .sweep import write_outputs

        return write_outputs(self, out, fmt=fmt, force=force)


def _num(value) -> float | None:
    value = float(value)
    return value if math.isfinite(value) else None


# --- one case ---------------------------------------------------------------------------
@dataclass
class Case:
    """One vehicle of a sweep flown again alone: its flight and its table row."""

    vehicle: int
    result: Any
    row: dict


def montecarlo_case(spec: MonteCarloSpec, i: int, *, log_every: int | None = None) -> Case:
    """Fly vehicle i of a sweep alone (the draws and random streams of (seed, i)): its row
    of the table, equal to the sweep's row whatever chunk it was flown in, and its flight,
    logged at the spec's rate (or every ``log_every`` periods: 1 for all; the row is
    always computed at the spec's rate).

    >>> spec = MonteCarloSpec("hover", population=Population(offset=0.2), seed=3, duration=0.5)
    >>> case = montecarlo_case(spec, 7)
    >>> case.row["vehicle"], case.result.n, case.row["dx0"] == float(case.result.states[0, 0, 0])
    (7, 1, True)
    """
    from .sweep import fly_chunk, reduce_chunk

    if isinstance(i, bool) or not isinstance(i, (int, np.integer)) or i < 0:
        raise InputError(f"vehicle index must be an integer >= 0, got {i!r}")
    res, draw = fly_chunk(spec, int(i), 1)
    chunk = reduce_chunk(spec, int(i), res, draw)
    row = {k: chunk[k][0].item() for k in COLUMNS}
    row["reason"] = FAILURES[row["failure"]]
    if log_every is not None and log_every != spec.log_every:
        res = fly_chunk(spec, int(i), 1, log_every)[0]
    return Case(vehicle=int(i), result=res, row=row)


def replay_case(result: MonteCarloResult, i: int, **kw) -> Case:
    """:func:`montecarlo_case` of vehicle i of a finished sweep."""
    if not 0 <= i < result.n:
        raise InputError(f"vehicle {i} is not in this sweep of {result.n} flights")
    return montecarlo_case(result.spec, i, **kw)


# --- the whole population ---------------------------------------------------------------
def montecarlo(mission: Mission | str = "circle", controller: Controller | str = "nlpd",
               population: Population | None = None, n: int = 100, seed: int = 0, *,
               chunk_size: int | str = "auto", scheduler: str | None = "local", workers: int | None = None,
               out: str | Path | None = None, resume: bool = True, force: bool = False, fmt: str = "csv",
               progress: Callable[[int, int], None] | None = None, connect_timeout: float = 10.0,
               **spec_options: Any) -> MonteCarloResult:
    """Fly a population of n vehicles and collect one row of metrics per flight.

    Parameters
    ----------
    mission, controller : names or objects
    population : Population
        The spreads; none (n identical vehicles) by default.
    n : int
        Number of flights (>= 1).
    seed : int
        Flight i depends on (seed, i) only.
    chunk_size : int or "auto"
        Vehicles per chunk (per task). "auto" keeps a chunk's log near 64 MB and gives each
        worker several chunks. The result does not depend on it.
    scheduler : "local", "none" or an address
        "local" (default): a Dask LocalCluster of ``workers`` processes (the machine's
        cores by default), one thread each; "none": in this process, numba using all cores;
        "tcp://host:port": an existing Dask cluster (unreachable: InputError). Worker
        processes are spawned, so a script using "local" needs the usual
        ``if __name__ == "__main__":`` guard.
    out : folder, optional
        Stream each chunk to ``out/chunks`` as it finishes and write the results at the end
        (see :mod:`quadcruise.sweep`). A folder holding part of the same sweep is resumed.
    resume, force : bool
        resume=False flies everything again; force replaces a folder holding something else.
    fmt : "csv" or "parquet"
        Format of the flights table.
    progress : callable, optional
        ``progress(done, total)`` after each chunk (flights done, resumed ones included);
        :class:`quadcruise.sweep.ProgressBar` prints a line on stderr.
    connect_timeout : float
        Seconds to wait for a scheduler given by address.
    **spec_options
        More :class:`MonteCarloSpec` fields: duration, dt, vehicle, log_dt, settle_band, ...
    """
    from .sweep import run_sweep

    spec = MonteCarloSpec(mission=mission, controller=controller, population=population or Population(),
                          seed=seed, **spec_options)
    return run_sweep(spec, n, chunk_size=chunk_size, scheduler=scheduler, workers=workers, out=out,
                     resume=resume, force=force, fmt=fmt, progress=progress, connect_timeout=connect_timeout)


# --- command line -----------------------------------------------------------------------
def _from_scenario(path: str, spreads: dict, n: int, seed: int):
    """The scenario, with its [montecarlo] table merged into spreads (explicit CLI values,
    those that differ from the defaults, win), and n and seed."""
    import dataclasses

    from .scenario import load_scenario

    sc = load_scenario(path)
    table = dict(sc.montecarlo)
    known = {f.name for f in dataclasses.fields(Population)} - {"environment", "noise"}
    unknown = set(table) - known - {"n", "seed"}
    if unknown:
        raise InputError(f"{path}: [montecarlo] unknown key(s) {', '.join(sorted(unknown))} "
                         f"(known: n, seed, {', '.join(sorted(known))})")
    defaults = {f.name: f.default for f in dataclasses.fields(Population)}
    for key, value in table.items():
        if key in spreads and spreads[key] == defaults.get(key):
            spreads[key] = value
    n = table.get("n", n) if n == 1000 else n
    seed = table.get("seed", sc.simulation.get("seed", seed)) if seed == 0 else seed
    return sc, n, seed


def parse_noise(text: str | None):
    """``position=STD,velocity=STD,angle=STD,rate=STD,delay=S`` -> SensorNoise (None: none).

    >>> parse_noise("position=0.01,delay=0.002").delay
    0.002
    """
    from .disturbances import SensorNoise

    if text is None or str(text).strip().lower() in ("", "none"):
        return None
    names = {"position": "position_std", "velocity": "velocity_std", "angle": "angle_std",
             "rate": "rate_std", "delay": "delay"}
    kw = {}
    for item in str(text).split(","):
        key, sep, value = item.partition("=")
        key = key.strip().lower()
        if not sep or key not in names:
            raise InputError(f"noise spec {text!r}: expected KEY=VALUE with KEY one of {', '.join(names)}")
        try:
            kw[names[key]] = float(value)
        except ValueError:
            raise InputError(f"noise spec {text!r}: {key} must be a number, got {value.strip()!r}") from None
    return SensorNoise(**kw)


def montecarlo_command(*, mission: str = "circle", controller: str = "nlpd", n: int = 1000, seed: int = 0,
                       duration: float | None = None, dt: float = 1e-3, wind: str | None = None,
                       wind_spread: float = 0.0, mass_spread: float = 0.0, inertia_spread: float = 0.0,
                       thrust_spread: float = 0.0, bandwidth_spread: float = 0.0, yaw_arm_spread: float = 0.0,
                       distribution: str = "normal", offset: float = 0.0, noise: str | None = None,
                       model_error: bool = True, chunk_size: str | int = "auto", scheduler: str = "local",
                       workers: int | None = None, connect_timeout: float = 10.0, out: str | None = None,
                       force: bool = False, resume: bool = True, fmt: str = "csv", case: int | None = None,
                       worst: int = 5, quiet: bool = False, scenario: str | None = None,
                       echo: Callable[[str], None] = print) -> MonteCarloResult | Case:
    """What ``quadcruise montecarlo`` runs: build the population, fly it, print the summary
    and the worst cases, write ``out``.

    With ``case=I`` only flight I is flown (alone; its row equals the sweep's) and, with
    ``out``, written with its traces and a figure: into ``out/case-00000I`` if ``out`` holds
    the sweep (whose options must be the same), else into ``out``. Bad input raises
    InputError before anything is written; ``chunk_size`` may be a number or "auto";
    ``wind`` is a :func:`~quadcruise.disturbances.parse_wind` spec and ``noise`` a
    :func:`parse_noise` one. A ``scenario`` file supplies the mission, controller, nominal
    vehicle, disturbances, sensor noise and simulation settings, and its ``[montecarlo]``
    table any of n, seed and the Population fields; options given explicitly win.
    """
    import sys

    from .disturbances import parse_wind
    from .sweep import ProgressBar

    if isinstance(chunk_size, str) and chunk_size != "auto":
        try:
            chunk_size = int(chunk_size)
        except ValueError:
            raise InputError(f"--chunk-size must be a whole number or auto, got {chunk_size!r}") from None
    env = parse_wind(wind) if wind is not None else None
    spreads = dict(mass_spread=mass_spread, inertia_spread=inertia_spread, thrust_spread=thrust_spread,
                   bandwidth_spread=bandwidth_spread, yaw_arm_spread=yaw_arm_spread, offset=offset,
                   wind_spread=wind_spread, distribution=distribution, model_error=model_error)
    sensor = parse_noise(noise)
    options: dict = dict(duration=duration, dt=dt)
    if scenario is not None:
        sc, n, seed = _from_scenario(scenario, spreads, n, seed)
        mission = sc.mission or mission
        controller = sc.controller or controller
        env = env if env is not None else sc.environment
        sensor = sensor if sensor is not None else sc.sensor_noise
        options.update(vehicle=sc.vehicle, duration=duration or sc.duration, dt=sc.simulation.get("dt", dt),
                       full_dynamics=sc.simulation.get("full_dynamics", False))
    population = Population(**spreads, environment=env if env is not None and env.parts else None, noise=sensor)
    if case is not None:
        from pathlib import Path

        from .sweep import _marker, write_case

        spec = MonteCarloSpec(mission=mission, controller=controller, population=population, seed=seed, **options)
        if isinstance(case, bool) or not isinstance(case, (int, np.integer)) or not 0 <= case < n:
            raise InputError(f"--case {case} is not one of the {n} flights")
        target = None if out is None else Path(out)
        meta = _marker(target) if target is not None and target.is_dir() else None
        if meta and meta.get("workflow") == "montecarlo":      # a sweep's folder: the case goes inside
            if meta.get("spec_hash") != spec.hash():
                raise InputError(f"{out}: holds a sweep flown with other options (spec {meta.get('spec_hash')}, "
                                 f"these give {spec.hash()}); give the sweep's options to replay its flight")
            target = target / f"case-{case:06d}"
        if target is not None:
            check_output_dir(target, force)
        found = montecarlo_case(spec, case)
        echo(f"flight {case} of seed {seed}: {found.row['reason']}, " + ", ".join(
            f"{k} = {found.row[k]:.4g}" for k in ("rmse_m", "max_error_m", "settling_time_5pct_s", "m")))
        if target is not None:
            write_case(found, target, fmt=fmt, force=True)
            echo(f"wrote the flight to {target}")
        return found
    bar = None if quiet else ProgressBar(sys.stderr)
    try:
        res = montecarlo(mission, controller, population, n, seed, chunk_size=chunk_size, scheduler=scheduler,
                         workers=workers, out=out, resume=resume, force=force, fmt=fmt, progress=bar,
                         connect_timeout=connect_timeout, **options)
    finally:
        if bar is not None:
            bar.close()
    echo(res.summary_text())
    if worst:
        cols = ["vehicle", "seed", "reason", "rmse_m", "max_error_m", "settling_time_5pct_s", "stop_time_s", "m"]
        echo(f"worst {worst} (fly one alone again with --case VEHICLE):")
        echo(res.worst(worst)[cols].to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    info = res.info
    echo(f"{info.get('flown', 0):,} flights flown ({info.get('resumed', 0):,} resumed) in {info.get('wall_s', 0):.1f} s "
         f"on {info.get('scheduler')}" + (f"; wrote {out}" if out is not None else ""))
    return res
