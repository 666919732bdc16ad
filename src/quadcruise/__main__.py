"""``python -m quadcruise`` runs the command line."""

from quadcruise.cli.main import run

run()
