"""The command line: parses strings, prints, and calls the library."""

from quadcruise.cli.main import main, run

__all__ = ["main", "run"]
