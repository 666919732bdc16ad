"""The installed package's version, read once from its metadata (a leaf: imports nothing of ours)."""

from __future__ import annotations

from importlib import metadata as _metadata

try:
    __version__ = _metadata.version("quadcruise")
except _metadata.PackageNotFoundError:  # running from a source tree that was not installed
    __version__ = "0.0.0+unknown"
