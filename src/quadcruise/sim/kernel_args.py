"""The engine kernels' arguments, declared once: :class:`KernelArgs` (the paper plant's kernel)
and :class:`RotorKernelArgs` (the rotor plant's) name them in order with their numba types, and
yield :data:`KERNEL_SIG` and :data:`ROTOR_KERNEL_SIG`.

The kernel itself takes them as a flat list (grouped into tuples it ran slower:
docs/performance.md); :func:`quadcruise.sim.engine.simulate` and
:class:`quadcruise.sim.stepper.Stepper` build a ``KernelArgs`` by name and hand it to
:func:`quadcruise.sim.engine.fly_vehicles`, which spreads it after the vehicle range.
"""

# no ``from __future__ import annotations``: the field annotations are the numba types themselves
from typing import NamedTuple

from numba import types

from quadcruise.layout import ControllerType, DisturbanceType, MissionType, ObserverType

_f8v = types.float64[::1]
_f8m = types.float64[:, ::1]
_f8c = types.float64[:, :, ::1]
_i8v = types.int64[::1]
_i8m = types.int64[:, ::1]
_u8m = types.uint64[:, ::1]


class KernelArgs(NamedTuple):
    """What the kernel reads and writes after the range of vehicles it flies, by role (the
    meaning of each: :func:`quadcruise.sim.engine.simulate`'s parameters; one row per vehicle).

    Time: ``t_grid``. Plant: ``x0``, ``vp``. Controller: ``vp_ctrl``, ``controller``, ``gains``,
    ``mem``. Mission: ``mission``, ``mp``. Disturbance: ``disturbance``, ``disturbed`` (False:
    still air), ``dp``, ``dmem``, ``rng``. Sensors: ``sensor_std``, ``sensor_delay`` (white noise on
    the truth, and its delay); or the observation stage (:mod:`quadcruise.sim.observe`):
    ``observer``, ``observed`` (False: skipped), ``op``, ``omem``, ``orng``, and its log ``log_obs``. Options:
    ``full``, ``max_step``, ``log_every``, ``limits``. Resuming: ``n_step``, ``clock``,
    ``carry``. Track checks: ``track`` (each vehicle's running figures, carried),
    ``track_plan`` (:mod:`quadcruise.sim.track_figures`). Outputs: ``log_x``, ``log_cmd``,
    ``log_ref``, ``log_obs``, ``x_final``, ``status``, ``t_stop``, ``saturated`` (and ``mem``, ``dmem``,
    ``rng``, ``omem``, ``orng`` written back).
    """

    t_grid: _f8v
    x0: _f8m
    vp: _f8m
    vp_ctrl: _f8m
    controller: ControllerType
    gains: _f8m
    mem: _f8m
    mission: MissionType
    mp: _f8m
    disturbance: DisturbanceType
    disturbed: types.boolean
    dp: _f8m
    dmem: _f8m
    rng: _u8m
    sensor_std: _f8m
    sensor_delay: types.int64
    observer: ObserverType
    observed: types.boolean
    op: _f8m
    omem: _f8m
    orng: _u8m
    full: types.boolean
    max_step: types.float64
    log_every: types.int64
    limits: _f8v
    n_step: types.int64
    clock: _i8m
    carry: _f8m
    track: _f8m
    track_plan: _f8v
    log_x: _f8c
    log_cmd: _f8c
    log_ref: _f8c
    log_obs: _f8c
    x_final: _f8m
    status: _i8v
    t_stop: _f8v
    saturated: _f8m


KERNEL_SIG = types.void(types.int64, types.int64, *KernelArgs.__annotations__.values())
"""The kernel's signature: the first and the stop vehicle of its range, then :class:`KernelArgs`."""


class RotorKernelArgs(NamedTuple):
    """The rotor plant's kernel's arguments after its range of vehicles
    (:func:`quadcruise.sim.rotor_batch.fly_rotor_vehicles` says what each holds): those of
    :class:`KernelArgs` of the same name mean the same, ``x0``/``x_final`` and ``vp`` (``rp``
    here) are the rotor plant's own; the rotor plant adds ``psi0`` (the yaw the initial
    quaternion's is read near), ``alloc`` (the duty-to-thrust matrix and the controller's kf),
    ``ground``, ``touchdown``, ``log_rotor`` and ``seen_final`` (the paper-layout final state), and
    has no ``full``.
    """

    t_grid: _f8v
    x0: _f8m
    psi0: _f8v
    rp: _f8m
    alloc: _f8m
    vp_ctrl: _f8m
    controller: ControllerType
    gains: _f8m
    mem: _f8m
    mission: MissionType
    mp: _f8m
    disturbance: DisturbanceType
    disturbed: types.boolean
    dp: _f8m
    dmem: _f8m
    rng: _u8m
    sensor_std: _f8m
    sensor_delay: types.int64
    observer: ObserverType
    observed: types.boolean
    op: _f8m
    omem: _f8m
    orng: _u8m
    max_step: types.float64
    log_every: types.int64
    limits: _f8v
    ground: types.boolean
    touchdown: _f8v
    n_step: types.int64
    clock: _i8m
    carry: _f8m
    track: _f8m
    track_plan: _f8v
    log_x: _f8c
    log_rotor: _f8c
    log_cmd: _f8c
    log_ref: _f8c
    log_obs: _f8c
    x_final: _f8m
    seen_final: _f8m
    status: _i8v
    t_stop: _f8v
    saturated: _f8m


ROTOR_KERNEL_SIG = types.void(types.int64, types.int64, *RotorKernelArgs.__annotations__.values())
"""The rotor kernel's signature: the first and the stop vehicle of its range, then :class:`RotorKernelArgs`."""

__all__ = ["KERNEL_SIG", "ROTOR_KERNEL_SIG", "KernelArgs", "RotorKernelArgs"]
