"""Gymnasium environments of quadcruise (the ``quadcruise[gym]`` extra), registered on import:

- ``quadcruise/Hover-v0``: hold a point from a random offset (a population's ``offset`` of
  0.3 m by default);
- ``quadcruise/Track-v0``: follow a reference ('circle' by default; 'square', 'waypoints',
  'minsnap', 'random' or any Mission through ``mission=``).

``gymnasium.make(id, action=...)`` gives one vehicle, ``gymnasium.make_vec(id, num_envs=N,
vectorization_mode="vector_entry_point")`` N of them in one compiled kernel call per step.
docs/gym.md describes the observations, actions, reward, termination and seeding.
"""

from __future__ import annotations

import gymnasium

from quadcruise.gym.env import QuadEnv, QuadVectorEnv
from quadcruise.montecarlo.population import Population

HOVER_POPULATION = Population(offset=0.3)
"""Hover-v0's default domain: the nominal vehicle, an initial offset of 0.3 m (one sigma) on each axis."""

ENVIRONMENTS = {
    "quadcruise/Hover-v0": {"mission": "hover", "population": HOVER_POPULATION},
    "quadcruise/Track-v0": {"mission": "circle"},
}

for _id, _kwargs in ENVIRONMENTS.items():
    if _id not in gymnasium.registry:
        gymnasium.register(
            id=_id,
            entry_point="quadcruise.gym.env:QuadEnv",
            vector_entry_point="quadcruise.gym.env:QuadVectorEnv",
            kwargs=_kwargs,
        )

__all__ = ["ENVIRONMENTS", "HOVER_POPULATION", "QuadEnv", "QuadVectorEnv"]
