"""Figures (matplotlib's object API, no pyplot): flights, comparisons, Monte Carlo sweeps and
animations. They take results duck-typed (any object with the arrays they read)."""

from quadcruise.plots.flight import REF_STYLE, plot_envelope, plot_flight, plot_paths, plot_reference, save_figure

__all__ = ["REF_STYLE", "plot_envelope", "plot_flight", "plot_paths", "plot_reference", "save_figure"]
