"""Feedback on long work, on stderr, on a terminal only: progress bars drawn by tqdm and one
line when numba starts compiling.

The library reports progress through a plain ``progress(done, total)`` callable and prints
nothing; :class:`Bar` is such a callable that draws a bar. Anything that takes one can be
given ``Bar("what it does", unit="what it counts")``: it draws from its first call and closes
when ``done`` reaches ``total`` (or at :meth:`Bar.close`, or when the command ends: see
:func:`close_bars`). An optional third argument, a short text, is shown after the bar.

Whether anything is shown is decided when it is drawn (:func:`feedback_on`): on a terminal
(stderr is a TTY) yes, else nothing at all, so a log or a pipe holds only the results. The
environment variable ``QUADCRUISE_PROGRESS`` overrides it: ``1`` shows the feedback
anywhere (the tests capture it so), ``0`` never.

Examples
--------
>>> import os
>>> os.environ["QUADCRUISE_PROGRESS"] = "0"
>>> bar = Bar("flying", unit="flight")
>>> for done in range(4):
...     bar(done, 3)                      # draws nothing: the feedback is off
>>> bar.closed
True
>>> del os.environ["QUADCRUISE_PROGRESS"]
"""

from __future__ import annotations

import contextlib
import os
import sys
import weakref
from collections.abc import Iterator

from tqdm import tqdm

__all__ = ["COMPILE_LINE", "ENV", "Bar", "close_bars", "compile_notice", "feedback_on"]

ENV = "QUADCRUISE_PROGRESS"
"""The environment variable that turns the feedback on (``1``) or off (``0``) anywhere."""

COMPILE_LINE = "compiling the engine and controllers for this machine, once (numba caches them on disk): about 5-15 s"
"""What :func:`compile_notice` says. Measured with an empty ``NUMBA_CACHE_DIR``, less the warm
run, on two shared cores: ``fly hover`` 6-8 s, ``analyze`` 7 s, ``montecarlo`` 10 s, ``compare``
(four controllers) 11-13 s."""

_OPEN: weakref.WeakSet = weakref.WeakSet()  # the bars drawn and not closed yet


def feedback_on() -> bool:
    """Whether feedback is shown: ``QUADCRUISE_PROGRESS`` if set (``1``/``0``), else whether stderr is a terminal."""
    value = os.environ.get(ENV, "").strip().lower()
    if value in ("1", "true", "yes", "on"):
        return True
    if value in ("0", "false", "no", "off"):
        return False
    try:
        return bool(sys.stderr.isatty())
    except (AttributeError, ValueError):  # no stderr, or a closed one
        return False


def _size() -> dict:
    """tqdm's size keywords: the terminal's, followed as it is resized; a terminal that
    reports no size (0 x 0, as a bare pseudo-terminal) gets 80 x 24, on which tqdm draws."""
    try:
        columns, lines = os.get_terminal_size(sys.stderr.fileno())
    except (AttributeError, OSError, ValueError):  # not a terminal: tqdm's defaults
        return {}
    return {"dynamic_ncols": True} if columns and lines else {"ncols": 80, "nrows": 24}


class _Tqdm(tqdm):
    """tqdm without its monitor thread (the bars here are updated often enough)."""

    monitor_interval = 0


class Bar:
    """A ``progress(done, total)`` callable that draws a bar on stderr (tqdm), when
    :func:`feedback_on`.

    Examples
    --------
    >>> with Bar("drawing", unit="frame") as bar:
    ...     bar(0, 2); bar(1, 2, "t = 0.5 s")
    """

    def __init__(self, label: str, unit: str = "step") -> None:
        self.label = label
        self.unit = unit
        self._bar: tqdm | None = None
        self.closed = False

    def __call__(self, done: int, total: int, text: str | None = None) -> None:
        """Show ``done`` of ``total``."""
        if self.closed:
            return
        if self._bar is None:
            self._bar = _Tqdm(
                total=total,
                initial=done,
                desc=self.label,
                unit=self.unit,
                file=sys.stderr,
                leave=False,
                disable=not feedback_on(),
                **_size(),
            )
            _OPEN.add(self)
        bar = self._bar
        if bar.disable:
            if done >= total:
                self.close()
            return
        bar.total = total
        if done >= total:
            self.close()
            return
        bar.update(done - bar.n)  # drawn at most every 0.1 s
        if text is not None:
            bar.set_postfix_str(text)  # drawn now

    def close(self) -> None:
        """Remove the bar (nothing happens if it is closed already)."""
        self.closed = True
        _OPEN.discard(self)
        if self._bar is not None:
            self._bar.close()

    def __enter__(self) -> Bar:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def close_bars() -> None:
    """Close every bar still open, e.g. before an error message."""
    for bar in list(_OPEN):
        bar.close()


@contextlib.contextmanager
def compile_notice() -> Iterator[None]:
    """Within it, say :data:`COMPILE_LINE` once on stderr when numba starts compiling."""
    # numba announces each compilation that misses its cache (its numba:compile event), which is
    # exactly when the wait comes; a later run loads the machine code from disk and says nothing.
    if not feedback_on():
        yield
        return
    from numba.core import event

    said: list[bool] = []

    class Notice(event.Listener):
        def on_start(self, ev) -> None:
            if not said:
                said.append(True)
                tqdm.write(COMPILE_LINE, file=sys.stderr)  # above any bar being drawn

        def on_end(self, ev) -> None:
            pass

    listener = Notice()
    event.register("numba:compile", listener)
    try:
        yield
    finally:
        event.unregister("numba:compile", listener)
