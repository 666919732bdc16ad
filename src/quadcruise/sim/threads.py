"""Flying a batch on numba's threads: the vehicle range is cut into pieces that a pool of Python
threads hands to a compiled kernel running without the GIL.

Vehicles are independent and each one's arithmetic does not depend on the piece it falls in, so
any split reproduces the single-thread flight bit for bit. (A ``prange`` kernel would do the
same, but numba's parallel passes lengthen the cold compile, and with one vehicle the idle
OpenMP thread spins: docs/performance.md.)
"""

from __future__ import annotations

import itertools
import os
import threading
from concurrent.futures import ThreadPoolExecutor

import numpy as np
from numba import config, get_num_threads

PIECES_PER_THREAD = 8
"""A batch is cut into this many pieces per thread, taken in turn by whichever thread is
free, so a thread whose vehicles stopped early (or ran slower) does not leave the others
waiting at the end."""

_pool: ThreadPoolExecutor | None = None
_pool_lock = threading.Lock()


def _forget_pool() -> None:
    """In a child made by ``os.fork``: drop the parent's pool, whose threads the child does
    not have (work handed to it would wait forever); the child's first batch makes its own."""
    global _pool, _pool_lock
    _pool, _pool_lock = None, threading.Lock()


if hasattr(os, "register_at_fork"):  # POSIX
    os.register_at_fork(after_in_child=_forget_pool)


def _helpers() -> ThreadPoolExecutor:
    """The process's pool of helper threads, made on first use (numba's threads can never exceed
    ``NUMBA_NUM_THREADS``)."""
    global _pool
    with _pool_lock:
        if _pool is None:
            _pool = ThreadPoolExecutor(
                max_workers=max(1, config.NUMBA_NUM_THREADS - 1), thread_name_prefix="quadcruise"
            )
        return _pool


def fly_in_pieces(
    kernel, n: int, args: tuple, pieces_per_thread: int = PIECES_PER_THREAD, after_piece=None, threads=None
) -> None:
    """Run ``kernel(first, stop, *args)`` over vehicles 0..n-1, on numba's number of threads
    (``numba.get_num_threads()``): one range on this thread when that is 1 or n is 1, else
    ``pieces_per_thread`` ranges per thread, handed out in turn.

    An exception raised by the kernel (a controller, mission or disturbance that raised) or
    by ``after_piece`` reaches the caller once every piece under way has ended; no piece starts
    after it.

    Parameters
    ----------
    kernel : compiled function
        Flies vehicles first..stop-1 of the batch arrays that follow (``nogil``).
    n : int
        Number of vehicles.
    args : KernelArgs
        The kernel's arguments after the vehicle range (its batch arrays, by role).
    pieces_per_thread : int
        Ranges per thread: fewer for short calls (a step), where each call's fixed cost counts.
    after_piece : callable, optional
        Called as ``after_piece(first, stop)`` on the thread that flew vehicles first..stop-1,
        right after it (their rows still in its cache).
    threads : int, optional
        At most this many threads; numba's number by default.
    """
    threads = min(n, get_num_threads() if threads is None else threads)
    if threads <= 1:
        kernel(0, n, *args)
        if after_piece is not None:
            after_piece(0, n)
        return
    bounds = np.linspace(0, n, min(n, pieces_per_thread * threads) + 1).round().astype(np.int64)
    pieces = itertools.count()  # next() on it is atomic under the GIL
    failed: list[BaseException] = []

    def work() -> None:
        while not failed and (k := next(pieces)) < bounds.shape[0] - 1:
            first, stop = int(bounds[k]), int(bounds[k + 1])
            try:
                kernel(first, stop, *args)
                if after_piece is not None:
                    after_piece(first, stop)
            except BaseException as exc:  # a controller, mission or disturbance raised: no more pieces
                failed.append(exc)

    helpers = [_helpers().submit(work) for _ in range(threads - 1)]
    work()
    for h in helpers:  # every piece ends before the caller sees the arrays, or the error
        h.result()
    if failed:
        raise failed[0]


class ThreadPlan:
    """How many threads a short call repeated many times (a step of the step-wise engine) runs on:
    one, or numba's number, whichever its recent calls took less time on.

    Handing a piece to a second thread costs a wake-up of that thread, and on a virtual machine
    whose other CPU is idle, of that CPU: more than the half of a short step it flies, while on a
    busy host two threads are faster (the figures: docs/gym.md, "Throughput"). So every
    :data:`KEEP` calls, :data:`TRIALS` calls on each are timed, in turn, and the one with the
    smaller median is kept. The split never changes a result (each vehicle's arithmetic is the
    same in any piece).
    """

    TRIALS = 8
    KEEP = 512

    def __init__(self) -> None:
        self.calls = 0
        self.times: dict[int, list[float]] = {}
        self.chosen = 1

    def threads(self) -> int:
        """The number of threads of the next call."""
        most = get_num_threads()
        k = self.calls % (2 * self.TRIALS + self.KEEP)
        if most <= 1:
            return 1
        if k < 2 * self.TRIALS:
            return 1 if k % 2 == 0 else most
        if k == 2 * self.TRIALS and self.times:
            self.chosen = min(self.times, key=lambda c: float(np.median(self.times[c])))
            self.times = {}
        return min(self.chosen, most)

    def record(self, threads: int, seconds: float) -> None:
        """Count a call made on ``threads`` threads that took ``seconds``."""
        if self.calls % (2 * self.TRIALS + self.KEEP) < 2 * self.TRIALS:
            self.times.setdefault(threads, []).append(seconds)
        self.calls += 1


__all__ = ["PIECES_PER_THREAD", "ThreadPlan", "fly_in_pieces"]
