"""What the package's objects promise one another, as :class:`typing.Protocol` classes (a leaf).

- :class:`ControllerLike`: anything that offers the engine a compiled function, its gains and
  its initial memory is a controller; the built-in ones subclass
  :class:`quadcruise.control.Controller`, a user's need not.
- :class:`ResultLike`: every result of the package (:class:`~quadcruise.SimResult`,
  :class:`~quadcruise.Comparison`, :class:`~quadcruise.montecarlo.MonteCarloResult`,
  :class:`~quadcruise.workflows.analysis.Linearization`) speaks one
  vocabulary: ``to_pandas()`` (its data as a DataFrame), ``summary()`` (its headline numbers: a
  :class:`~quadcruise.metrics.summary.Summary`, a mapping that prints as a readable table),
  ``plot()`` (a matplotlib Figure) and ``write(folder)`` (a folder written whole or not at all).
"""

from __future__ import annotations

from typing import Any, Protocol, runtime_checkable

__all__ = ["ControllerLike", "ResultLike"]


@runtime_checkable
class ControllerLike(Protocol):
    """A controller the engine can fly.

    Attributes
    ----------
    name : str
        A short name, recorded with the flight.
    function : numba dispatcher
        Compiled with :data:`quadcruise.layout.CONTROLLER_SIG`:
        ``f(t, dt, x, ref, vp, gains, mem, cmd)``.
    """

    name: str

    @property
    def function(self) -> Any:
        """The compiled control law."""

    def gains(self) -> Any:
        """The parameters of the compiled function.

        Returns
        -------
        numpy.ndarray
            The flat float64 vector it reads as ``gains`` (or (N, G) rows, one per vehicle).
        """

    def memory(self) -> Any:
        """The controller's initial memory.

        Returns
        -------
        numpy.ndarray
            The float64 vector the compiled function reads and writes as ``mem``.
        """


@runtime_checkable
class ResultLike(Protocol):
    """The vocabulary of every result."""

    def to_pandas(self) -> Any:
        """The result's data.

        Returns
        -------
        pandas.DataFrame
        """

    def summary(self) -> Any:
        """The headline numbers.

        Returns
        -------
        quadcruise.metrics.summary.Summary
            A mapping that prints as a readable table.
        """

    def plot(self) -> Any:
        """A figure of the result.

        Returns
        -------
        matplotlib.figure.Figure
        """

    def write(self, out: Any) -> Any:
        """Write the result into a folder, whole or not at all.

        Parameters
        ----------
        out : str or os.PathLike
            The folder.

        Returns
        -------
        pathlib.Path
            The folder written.
        """
