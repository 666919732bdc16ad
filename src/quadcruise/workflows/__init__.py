"""What a user runs: :mod:`~quadcruise.workflows.fly`, :mod:`~quadcruise.workflows.replay`,
:mod:`~quadcruise.workflows.compare`, :mod:`~quadcruise.workflows.reproduce` (the paper),
:mod:`~quadcruise.workflows.analysis` (the loop linearised about hover: ``linearize``, ``Linearization``) and
:mod:`~quadcruise.workflows.scenario` (TOML files).

The functions are re-exported by :mod:`quadcruise` itself (``qc.fly``, ``qc.compare``, ...);
this package re-exports nothing, so that ``quadcruise.workflows.fly`` is always the module.
"""
