"""The disturbances a flight meets, composed: :class:`Environment` hands the engine ONE
compiled disturbance, :func:`environment_disturbance`, with a flat parameter row per vehicle
(:data:`ENVIRONMENT_PARAMS`; absent parts are off by a 0/1 column) and the turbulence's memory
(:data:`~quadcruise.disturbances.turbulence.DRYDEN_MEMORY`). Batched (any numeric field of a
part may hold one value per vehicle) and seeded through the engine's per-vehicle generator.

Each period [t, t + dt] it writes into ext: the force (earth frame) and torque (body frame) of
:class:`~quadcruise.disturbances.faults.ExternalForce`; the wind (earth frame) =
:class:`~quadcruise.disturbances.wind.ConstantWind` + :class:`~quadcruise.disturbances.wind.Gust`
+ :class:`~quadcruise.disturbances.turbulence.Turbulence`, which acts only through the vehicle's
drag; and the rotor effectiveness (:class:`~quadcruise.disturbances.faults.RotorLoss`). t is the
period's start; ext is held over it. The parts' formulas are in their modules (``wind``,
``turbulence``, ``faults``).

Examples
--------
>>> import quadcruise as qc
>>> from quadcruise.disturbances import DEFAULT_DRAG, ConstantWind, Environment, Gust, Turbulence
>>> env = Environment(wind=ConstantWind(velocity=(2.0, 0.0, 0.0)), turbulence=Turbulence(intensity="light"))
>>> sorted(env.kwargs(3)), env.params(3).shape, env.needs_drag
(['disturbance', 'disturbance_memory', 'disturbance_params'], (3, 25), True)
>>> vehicle = qc.Vehicle.paper().replace(**DEFAULT_DRAG)     # wind needs drag to act
>>> res = qc.fly("hover", vehicle=vehicle, n=3, duration=2.0, seed=1, environment=env)
>>> res.ok.tolist(), bool(res.states[0, -1, 0] != res.states[1, -1, 0])
([True, True, True], True)
>>> three = Environment(gust=Gust(amplitude=([1.0, 2.0, 3.0], 0.0, 0.0), start=1.0, duration=2.0))
>>> three.batch_size, three.params()[:, ENV_GUST_AMPLITUDE].tolist()    # one gust peak per vehicle
(3, [1.0, 2.0, 3.0])
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from quadcruise.disturbances.faults import ExternalForce, RotorLoss
from quadcruise.disturbances.part import Part
from quadcruise.disturbances.turbulence import DRY_STARTED, DRYDEN_MEMORY, Turbulence, dryden_step
from quadcruise.disturbances.wind import ConstantWind, Gust
from quadcruise.errors import InputError
from quadcruise.fields import Validated, instance_of, unit_field
from quadcruise.layout import DISTURBANCE_SIG, EXT_E1, EXT_FX, EXT_TX, EXT_WX, Row

__all__ = ["ENVIRONMENT_PARAMS", "Environment", "PARAMS_SIZE", "MEMORY_SIZE", "SLOTS", "environment_disturbance"]

ENVIRONMENT_PARAMS = Row.of(
    "environment parameters",
    ("force", 3),
    ("torque", 3),
    ("wind", 3),
    "gust_on",
    ("gust_amplitude", 3),
    "gust_start",
    "gust_duration",
    "turbulence_on",
    ("sigma", 3),
    "t_u",
    "t_w",
    "loss_on",
    "loss_rotor",
    "loss_effectiveness",
    "loss_time",
    prefix="ENV_",
)
"""A vehicle's disturbance parameters: force (earth frame) [N] and torque (body frame) [N m];
steady wind [m/s]; gust (on 0/1, peak A [m/s] x, y, z, start [s], duration [s]); turbulence
(on, sigma_u, sigma_v, sigma_w [m/s], T_u, T_w [s]); rotor loss (on, rotor index 0-3,
effectiveness 1 - fraction [-], time [s])."""
(
    ENV_FORCE,
    ENV_TORQUE,
    ENV_WIND,
    ENV_GUST_ON,
    ENV_GUST_AMPLITUDE,
    ENV_GUST_START,
    ENV_GUST_DURATION,
    ENV_TURBULENCE_ON,
    ENV_SIGMA,
    ENV_T_U,
    ENV_T_W,
    ENV_LOSS_ON,
    ENV_LOSS_ROTOR,
    ENV_LOSS_EFFECTIVENESS,
    ENV_LOSS_TIME,
) = ENVIRONMENT_PARAMS.offsets
PARAMS_SIZE = ENVIRONMENT_PARAMS.size
MEMORY_SIZE = DRYDEN_MEMORY.size


# The disturbance follows the scalar-only rule of quadcruise.sim.fastmath: rng[0] and the
# started flag loaded first and stored last, no trailing if, the normals from fastmath.five_normals.


@njit(DISTURBANCE_SIG, cache=True, error_model="numpy")
def environment_disturbance(t, dt, x, dp, dmem, rng, ext):
    """The composite disturbance of :class:`Environment` (the formulas: each part's module).

    Compiled with :data:`quadcruise.layout.DISTURBANCE_SIG`; the engine calls it once per
    control period and holds ``ext`` over the period.

    Parameters
    ----------
    t : float
        Time at the start of the period [s] (the gust's phase, the rotor loss's onset).
    dt : float
        Length of the period [s], > 0 (the turbulence filters' step).
    x : numpy.ndarray
        The true state, STATE_SIZE (16) float64 entries (not read: no part depends on it).
    dp : numpy.ndarray
        The vehicle's parameter row, :data:`ENVIRONMENT_PARAMS` (25 float64 entries,
        :meth:`Environment.params`): force (earth frame) [N] and torque (body frame)
        [N m]; steady wind [m/s]; gust (on 0/1, peak A [m/s] x, y, z, start [s], duration
        [s]); turbulence (on, sigma_u, sigma_v, sigma_w [m/s], T_u, T_w [s]); rotor loss
        (on, rotor index 0-3, effectiveness 1 - fraction [-], time [s]).
    dmem : numpy.ndarray
        The vehicle's disturbance memory, ``DRYDEN_MEMORY`` (19 float64 entries), zeros at the
        start of a flight (:meth:`Environment.memory`), updated in place: a started flag,
        the Dryden filters' states (dimensionless, multiplied by the sigmas on output),
        the period the coefficients were computed for [s] and the coefficients.
    rng : numpy.ndarray
        The vehicle's random generator state, (1,) uint64 (:mod:`quadcruise.sim.rng`),
        advanced in place when there is turbulence.
    ext : numpy.ndarray
        Output, EXT_SIZE (13) float64 entries, all written (``EXT_*`` of
        :mod:`quadcruise.layout`): force, earth frame [N]; torque, body frame [N m]; wind
        velocity, earth frame [m/s] (steady + gust + turbulence); each rotor's
        effectiveness [-] (1 healthy).

    Examples
    --------
    >>> import numpy as np
    >>> env = Environment(wind=ConstantWind(velocity=(2.0, 0.0, 0.0)),
    ...                   rotor_loss=RotorLoss(rotor=2, fraction=0.3, time=0.0))
    >>> ext = np.zeros(13)
    >>> environment_disturbance(0.0, 0.001, np.zeros(16), env.params()[0], env.memory()[0],
    ...                         np.zeros(1, np.uint64), ext)
    >>> ext[6:9].tolist(), ext[9:].tolist()                 # wind; rotor 2 at 70 %
    ([2.0, 0.0, 0.0], [1.0, 0.7, 1.0, 1.0])
    """
    state, started = rng[0], dmem[DRY_STARTED]  # loaded first, stored last (see the note above)
    for j in range(3):
        ext[EXT_FX + j] = dp[ENV_FORCE + j]
        ext[EXT_TX + j] = dp[ENV_TORQUE + j]
        ext[EXT_WX + j] = dp[ENV_WIND + j]
    if dp[ENV_GUST_ON] != 0.0:
        s = t - dp[ENV_GUST_START]
        if 0.0 <= s <= dp[ENV_GUST_DURATION]:
            k = 0.5 * (1.0 - math.cos(2.0 * math.pi * s / dp[ENV_GUST_DURATION]))
            for j in range(3):
                ext[EXT_WX + j] += k * dp[ENV_GUST_AMPLITUDE + j]
    if dp[ENV_TURBULENCE_ON] != 0.0:  # Dryden: output at t, then advance the filters to t + dt
        sigma_u, sigma_v, sigma_w = dp[ENV_SIGMA], dp[ENV_SIGMA + 1], dp[ENV_SIGMA + 2]
        started, state = dryden_step(dt, sigma_u, sigma_v, sigma_w, dp[ENV_T_U], dp[ENV_T_W], dmem, started, state, ext)
    lost = dp[ENV_LOSS_ON] != 0.0 and t >= dp[ENV_LOSS_TIME] - 1e-9 * (1.0 + abs(dp[ENV_LOSS_TIME]))
    for j in range(4):
        ext[EXT_E1 + j] = dp[ENV_LOSS_EFFECTIVENESS] if lost and dp[ENV_LOSS_ROTOR] == j else 1.0
    rng[0], dmem[DRY_STARTED] = state, started


SLOTS = {"wind": ConstantWind, "gust": Gust, "turbulence": Turbulence, "rotor_loss": RotorLoss, "force": ExternalForce}
"""The parts of an :class:`Environment`, by slot."""


@dataclass(frozen=True)
class Environment(Validated):
    """The disturbances a flight meets, each part optional: ``fly(..., environment=env)``.

    Parameters
    ----------
    wind : ConstantWind, optional
        Steady wind.
    gust : Gust, optional
        A 1 - cosine gust, added to the wind.
    turbulence : Turbulence, optional
        Dryden turbulence, added to the wind.
    rotor_loss : RotorLoss, optional
        The loss of part of one rotor's thrust.
    force : ExternalForce, optional
        A constant external force and torque.

    Examples
    --------
    >>> Environment(gust=Gust()).units()["gust.duration"]
    's'
    """

    wind: ConstantWind | None = unit_field(None, "-", "steady wind", instance_of(ConstantWind))
    gust: Gust | None = unit_field(None, "-", "1 - cosine gust", instance_of(Gust))
    turbulence: Turbulence | None = unit_field(None, "-", "Dryden turbulence", instance_of(Turbulence))
    rotor_loss: RotorLoss | None = unit_field(None, "-", "loss of a rotor's thrust", instance_of(RotorLoss))
    force: ExternalForce | None = unit_field(None, "-", "external force and torque", instance_of(ExternalForce))
    name = "environment"

    @classmethod
    def from_parts(cls, *parts: Part) -> Environment:
        """Each part into its slot (one of each kind).

        Parameters
        ----------
        *parts : ConstantWind, Gust, Turbulence, RotorLoss or ExternalForce
            The parts, in any order, at most one of each kind.

        Returns
        -------
        Environment
            The parts in their slots, the others empty.

        Raises
        ------
        InputError
            A part of another type, or a second part of one kind.

        Examples
        --------
        >>> sorted(Environment.from_parts(Gust(), ConstantWind()).parts)
        ['gust', 'wind']
        """
        slots: dict = {}
        for part in parts:
            slot = next((s for s, c in SLOTS.items() if isinstance(part, c)), None)
            if slot is None or slot in slots:
                raise InputError(f"{'unknown' if slot is None else 'a second'} disturbance part {part!r}")
            slots[slot] = part
        return cls(**slots)

    @classmethod
    def from_dict(cls, d: dict) -> Environment:
        """Inverse of :meth:`to_dict`.

        Parameters
        ----------
        d : dict
            Slot name -> a part's dict (with its ``model`` key, which is ignored) or None.

        Returns
        -------
        Environment

        Examples
        --------
        >>> env = Environment(gust=Gust(start=2.0))
        >>> Environment.from_dict(env.to_dict()).gust.start
        2.0
        """
        return cls(**{k: v and SLOTS[k](**{a: b for a, b in v.items() if a != "model"}) for k, v in d.items()})

    def to_dict(self) -> dict:
        """Plain values of every slot (for result bundles and :meth:`from_dict`).

        Returns
        -------
        dict
            Slot name (``wind``, ``gust``, ``turbulence``, ``rotor_loss``, ``force``) -> the
            part's fields as plain values with its ``model`` name, or None if empty.
        """
        return {s: getattr(self, s) and getattr(self, s).to_dict() for s in SLOTS}

    @property
    def parts(self) -> dict:
        """The parts present, by slot (empty: still air)."""
        return {s: getattr(self, s) for s in SLOTS if getattr(self, s) is not None}

    @property
    def function(self):
        """The compiled composite disturbance (``DISTURBANCE_SIG``)."""
        return environment_disturbance

    @property
    def needs_drag(self) -> bool:
        """True if there is wind: it acts only through the vehicle's drag."""
        return any(getattr(self, s) is not None for s in ("wind", "gust", "turbulence"))

    @property
    def batch_size(self) -> int | None:
        """N if a field is per-vehicle, else None."""
        return Part.one_size(set().union(*(p.sizes() for p in self.parts.values())), "disturbance")

    def params(self, n: int | None = None) -> np.ndarray:
        """(N, PARAMS_SIZE) float64 parameter rows; per-vehicle arrays must have N values.

        Parameters
        ----------
        n : int, optional
            Number of vehicles N; by default the batch size (1 if no field is per-vehicle).

        Returns
        -------
        numpy.ndarray
            (N, PARAMS_SIZE) float64: the ``dp`` rows of :func:`environment_disturbance`
            (absent parts are zeros, their on-column 0).

        Raises
        ------
        InputError
            Per-vehicle fields whose length is not n.
        """
        size = self.batch_size
        n = (size or 1) if n is None else int(n)
        if size is not None and size != n:
            raise InputError(f"disturbance fields have {size} values but {n} vehicles were asked for")
        values: dict = {}
        if (f := self.force) is not None:
            values.update(force=f.force, torque=f.torque)
        if self.wind is not None:
            values.update(wind=self.wind.velocity)
        if (g := self.gust) is not None:
            values.update(gust_on=1.0, gust_amplitude=g.amplitude, gust_start=g.start, gust_duration=g.duration)
        if (tb := self.turbulence) is not None:
            tu, _, tw = tb.time_constants()
            values.update(turbulence_on=1.0, sigma=tb.sigmas(), t_u=tu, t_w=tw)
        if (r := self.rotor_loss) is not None:
            values.update(
                loss_on=1.0,
                loss_rotor=np.subtract(r.rotor, 1),
                loss_effectiveness=np.subtract(1, r.fraction),
                loss_time=r.time,
            )
        return ENVIRONMENT_PARAMS.pack(values, n=n, default=0.0)

    def memory(self, n: int | None = None) -> np.ndarray:
        """(N, MEMORY_SIZE) zeros: the turbulence filters start on the first period.

        Parameters
        ----------
        n : int, optional
            Number of vehicles N; by default the batch size (1 if no field is per-vehicle).

        Returns
        -------
        numpy.ndarray
            (N, MEMORY_SIZE) float64 zeros: the ``dmem`` rows of
            :func:`environment_disturbance`.
        """
        return np.zeros(((self.batch_size or 1) if n is None else int(n), MEMORY_SIZE))

    def kwargs(self, n: int | None = None) -> dict:
        """``disturbance``, ``disturbance_params`` and ``disturbance_memory`` for simulate/fly
        ((N, ...) rows; one row each, which the engine gives every vehicle, if n is None and
        no field is per-vehicle).

        Parameters
        ----------
        n : int, optional
            Number of vehicles N.

        Returns
        -------
        dict
            ``disturbance``: the compiled function; ``disturbance_params``: :meth:`params`;
            ``disturbance_memory``: :meth:`memory` (each a single row when n is None and no
            field is per-vehicle).
        """
        one = n is None and self.batch_size is None
        dp, dm = self.params(n), self.memory(n)
        return {
            "disturbance": self.function,
            "disturbance_params": dp[0] if one else dp,
            "disturbance_memory": dm[0] if one else dm,
        }
