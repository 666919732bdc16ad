"""Fields with units: one declaration and one validation for every parameter object of the
package (the vehicle, the missions, the disturbance parts, the controllers and their gains).
The checks of a value live in :mod:`~quadcruise.fields.checks`, the declaration and the
validation in :mod:`~quadcruise.fields.declaration`; the command line's ``KEY=VALUE`` options
are read by :mod:`quadcruise.cli.assignments`.

A field is declared with :func:`unit_field`: its default, its unit [SI], what it means, and a
:class:`Check`. A frozen dataclass that derives from :class:`Validated` runs :func:`validate`
when it is made: each value is checked and stored in its one form (a number as a float, a
per-vehicle array as a read-only float copy, a pair as a tuple), and a bad one raises a
one-line :class:`~quadcruise.errors.InputError` naming the owner, the field, its meaning and
unit, and what was wrong, e.g.
``circle field 'radius' (circle radius, m) must be > 0, got 0.0``.

The checks by name: ``real`` (a finite number), ``pos`` (> 0), ``nonneg`` (>= 0), ``nonzero``, ``frac``
(in [0, 1]), ``sign`` (+1 or -1), ``whole`` (a whole number >= 0), ``flag`` (true or false),
``pair`` and ``vec`` (2 or 3 numbers), ``choice`` (one of the field's ``choices``); and made
to measure: :func:`between` (a range, open or closed at each end), :func:`one_of`,
:func:`vector` (n numbers), :func:`instance_of` (an object of a class) and :class:`Check`
itself (any predicate). ``batch=True`` lets a numeric field hold one value per vehicle
(a 1-D array); ``optional=True`` (the default when the default is None) lets it be None.

Examples
--------
>>> from dataclasses import dataclass
>>> @dataclass(frozen=True)
... class Spring(Validated):
...     name = "spring"
...     stiffness: float = unit_field(100.0, "N/m", "spring rate", "pos")
...     preload: float = unit_field(0.0, "N", "force at rest", "nonneg", batch=True)
>>> Spring(preload=[1, 2]).preload
array([1., 2.])
>>> Spring.units()
{'stiffness': 'N/m', 'preload': 'N'}
>>> Spring(stiffness=-1)
Traceback (most recent call last):
    ...
quadcruise.errors.InputError: spring field 'stiffness' (spring rate, N/m) must be > 0, got -1.0
"""

from quadcruise.fields.checks import CHECKS, Check, between, check_number, check_value, instance_of, one_of, vector
from quadcruise.fields.declaration import Validated, unit_field, units_of, validate
from quadcruise.fields.declaration import owner_name as owner_name  # not exported, kept importable

__all__ = [
    "CHECKS",
    "Check",
    "Validated",
    "between",
    "check_number",
    "check_value",
    "instance_of",
    "one_of",
    "unit_field",
    "units_of",
    "validate",
    "vector",
]
