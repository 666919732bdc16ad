"""The vehicles a flight log is consistent with: identified parameters drawn from their estimate.

``quadcruise identify`` writes each parameter's estimate and 95 % interval (``identify.json``);
:class:`Identified` reads them and draws, for vehicle i of a sweep::

    theta_i = theta_hat + L z_i,    L L^T = C,    z_i ~ N(0, I) truncated to [-3, 3]

with ``C`` the estimates' covariance: ``identify.json``'s ``"covariance"`` (``{"names": [...],
"matrix": [[...]]}``, in the parameters' units) for the parameters it lists, else the diagonal
of the intervals, ``sigma = (hi - lo) / (2 x 1.959964)`` (independent draws;
:attr:`Identified.correlated` is True only when the log's covariance covers every parameter
drawn). Only parameters identified from the log and fields of the vehicle flown are drawn
(``K``, ``Jxx``, ``omega``, ... ; ``kf``, ``tau_up``, ... for a rotor plant); the rest keep the
nominal vehicle's values.

Randomness: vehicle i's ``z_i`` come only from ``SeedSequence([seed, i], spawn_key=(DRAW_KEY,))``
(its own stream: the population's other draws are not moved).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from quadcruise.errors import InputError
from quadcruise.sim.fastmath import seeded_draws

DRAW_KEY = 2
"""spawn_key of the identified parameters' draws (the population's own unit draws use 1)."""
Z95 = 1.959963984540054
"""The standard normal's 97.5 % quantile: a 95 % interval is +-Z95 standard deviations."""
CLIP = 3.0
"""Largest |z| drawn (as the population's normal draws: a draw beyond is drawn again from the same stream)."""


@dataclass(frozen=True)
class Identified:
    """Identified parameters and their covariance, to draw vehicles from.

    Parameters
    ----------
    names : tuple of str
        The drawn parameters (fields of the vehicle flown).
    mean : tuple of float
        Their estimates.
    covariance : tuple of tuple of float
        Their covariance, in their units squared.
    correlated : bool
        True when the covariance is the log's (``identify.json`` ``"covariance"``) for every
        parameter; False when some or all of it is the intervals' diagonal (independent draws).
    source : str
        Where they were read.

    Examples
    --------
    >>> ident = Identified(("Jxx", "Jyy"), (0.02, 0.025), ((1e-8, 0.5e-8), (0.5e-8, 1e-8)), True, "x")
    >>> values = ident.draw(seed=1, ids=np.arange(20000))
    >>> np.round(np.corrcoef(values.T)[0, 1], 1), np.round(values.std(axis=0) / 1e-4, 1).tolist()
    (np.float64(0.5), [1.0, 1.0])
    """

    names: tuple
    mean: tuple
    covariance: tuple
    correlated: bool
    source: str

    def __post_init__(self) -> None:
        cov = np.asarray(self.covariance, dtype=np.float64)
        k = len(self.names)
        if cov.shape != (k, k) or len(self.mean) != k:
            raise InputError(f"{self.source}: the covariance must be {k} x {k}, one row per parameter")
        if not np.all(np.isfinite(cov)) or not np.allclose(cov, cov.T, rtol=1e-6, atol=0.0):
            raise InputError(f"{self.source}: the covariance is not a finite symmetric matrix")
        eig = np.linalg.eigvalsh(cov) if k else np.zeros(0)
        if k and eig.min() < -1e-9 * max(eig.max(), 0.0):
            raise InputError(f"{self.source}: the covariance is not positive semi-definite")
        sigma = np.sqrt(np.clip(np.diag(cov), 0.0, None))
        low = np.asarray(self.mean) - CLIP * math.sqrt(max(k, 1)) * sigma
        for name, value, lo in zip(self.names, self.mean, low, strict=True):
            if lo <= 0.0:
                raise InputError(
                    f"{self.source}: {name} = {value:g} is too uncertain to draw from (its interval reaches 0 within "
                    f"{CLIP:g} sigma): identify it from a log that excites it more"
                )

    @classmethod
    def read(cls, source, fields=None) -> Identified:
        """The identified parameters of ``source`` (``identify.json`` or its folder) that are among ``fields``.

        Parameters
        ----------
        source : str or os.PathLike
            ``identify.json``, or the folder ``quadcruise identify --out`` wrote.
        fields : collection of str, optional
            The vehicle's field names: only those are drawn (default: the identification's base
            vehicle's, ``"base_vehicle"``).

        Returns
        -------
        Identified

        Raises
        ------
        InputError
            No such file, not an identification, identified per unit mass (no mass), no
            parameter to draw.
        """
        path = Path(source)
        if path.is_dir():
            path = path / "identify.json"
        if not path.is_file():
            raise InputError(
                f"{path}: no such file (an identification is the identify.json that identify --out writes)"
            )
        try:
            data = json.loads(path.read_text())
        except (json.JSONDecodeError, UnicodeDecodeError) as exc:
            raise InputError(f"{path}: not an identification (not JSON: {exc})") from None
        params = data.get("parameters") if isinstance(data, dict) else None
        if not isinstance(params, dict):
            raise InputError(f"{path}: not an identification (no 'parameters')")
        if data.get("verdict") == "does not fit":
            why = (data.get("verdict_reasons") or ["see its report"])[0]
            raise InputError(
                f"{path}: identify's verdict: the model does not fit the log ({why}); its values describe no vehicle "
                "to draw from"
            )
        if data.get("per_unit_mass"):
            raise InputError(
                f"{path}: identified per unit mass (no --mass): the vehicles cannot be drawn; identify with --mass"
            )
        if fields is None:
            fields = set(data.get("base_vehicle") or {})
        names, mean, sigma = [], [], []
        for name, p in params.items():
            ci = p.get("ci95") or [None, None]
            if name not in fields or not p.get("identifiable") or None in ci:
                continue
            lo, hi = float(ci[0]), float(ci[1])
            if not (math.isfinite(lo) and math.isfinite(hi) and hi >= lo):
                raise InputError(f"{path}: parameter {name}: its interval {ci} is not finite")
            names.append(name)
            mean.append(float(p["value"]))
            sigma.append((hi - lo) / (2.0 * Z95))
        if not names:
            raise InputError(f"{path}: no identified parameter of the vehicle to draw")
        cov = np.diag(np.square(sigma))
        given = data.get("covariance")
        correlated = False
        if given is not None:  # its block where it covers the drawn parameters, the intervals' elsewhere
            try:
                listed = [str(n) for n in given["names"]]
                full = np.asarray(given["matrix"], dtype=np.float64)
            except (KeyError, TypeError, ValueError):
                raise InputError(f"{path}: 'covariance' must be {{'names': [...], 'matrix': [[...]]}}") from None
            if full.shape != (len(listed), len(listed)):
                raise InputError(f"{path}: 'covariance': the matrix must have one row and column per name")
            here = [i for i, n in enumerate(names) if n in listed]
            there = [listed.index(names[i]) for i in here]
            cov[np.ix_(here, here)] = full[np.ix_(there, there)]
            correlated = len(here) == len(names)
        return cls(
            tuple(names),
            tuple(mean),
            tuple(map(tuple, cov.tolist())),
            bool(correlated),
            str(path),
        )

    def draw(self, seed: int, ids) -> np.ndarray:
        """The drawn parameters of vehicles ``ids``: (len(ids), len(names)), columns as :attr:`names`."""
        ids = np.ravel(ids)
        k = len(self.names)
        z = seeded_draws(int(seed), ids, DRAW_KEY, k, True)
        for r in np.flatnonzero(np.any(np.abs(z) > CLIP, axis=1)):  # truncated: drawn again from the same stream
            spare = 4 * k
            while True:
                more = seeded_draws(int(seed), ids[r : r + 1], DRAW_KEY, k + spare, True)[0, k:]
                more = more[np.abs(more) <= CLIP]
                bad = np.flatnonzero(np.abs(z[r]) > CLIP)
                if more.size >= bad.size:
                    z[r, bad] = more[: bad.size]
                    break
                spare *= 2
        cov = np.asarray(self.covariance, dtype=np.float64)
        w, v = np.linalg.eigh(cov)  # L = V sqrt(W): any semi-definite C
        root = v * np.sqrt(np.clip(w, 0.0, None))
        return np.asarray(self.mean) + z @ root.T

    @classmethod
    def from_dict(cls, data: dict) -> Identified:
        """An :class:`Identified` from :meth:`to_dict`'s values (a sweep's ``scenario.toml``)."""
        try:
            return cls(
                tuple(str(n) for n in data["names"]),
                tuple(float(v) for v in data["mean"]),
                tuple(tuple(float(v) for v in row) for row in data["covariance"]),
                bool(data["correlated"]),
                str(data["source"]),
            )
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"identified: not an identification's draw ({exc!r} missing or wrong)") from None

    def to_dict(self) -> dict:
        """Plain values (for the sweep's configuration and its hash)."""
        return {
            "source": self.source,
            "names": list(self.names),
            "mean": list(self.mean),
            "covariance": [list(r) for r in self.covariance],
            "correlated": self.correlated,
        }
