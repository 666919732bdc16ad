"""A result's headline numbers: a read-only mapping (for code and JSON) that prints as a table
(for people)."""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from typing import Any

__all__ = ["Summary"]


class Summary(Mapping):
    """The headline numbers of a result.

    Parameters
    ----------
    data : dict
        The numbers, nested as the result chooses (plain values: JSON-ready).
    text : str
        How they read in a terminal; ``str(summary)`` and ``print(summary)`` give it.

    Examples
    --------
    >>> s = Summary({"flights": 3, "failures": {"count": 0}}, "3 flights, none failed")
    >>> s["failures"]["count"], str(s)
    (0, '3 flights, none failed')
    """

    def __init__(self, data: dict, text: str) -> None:
        self._data = dict(data)
        self._text = text

    def __getitem__(self, key: str) -> Any:
        return self._data[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self._data)

    def __len__(self) -> int:
        return len(self._data)

    def __str__(self) -> str:
        return self._text

    def __repr__(self) -> str:
        return self._text

    def to_dict(self) -> dict:
        """The numbers as a plain dict.

        Returns
        -------
        dict
        """
        return dict(self._data)
