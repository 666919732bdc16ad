"""``python -m quadcruise`` runs the command line."""

from .cli import run

run()
