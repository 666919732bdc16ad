"""Run as a script: a batched fly in this process, then one in a child made by ``os.fork`` and
one in a ``multiprocessing`` fork child; prints one line per child, ``<how> <exit code>``
(``<how> hung`` when the child did not finish within the seconds given as argv[1])."""

import multiprocessing
import os
import sys
import time

import quadcruise as qc


def batch() -> bool:
    return bool(qc.fly("hover", "nlpd", n=4, duration=0.2).ok.all())


def child() -> None:
    os._exit(0 if batch() else 1)


def wait(pid: int, seconds: float) -> str:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            return str(os.waitstatus_to_exitcode(status))
        time.sleep(0.05)
    os.kill(pid, 9)
    os.waitpid(pid, 0)
    return "hung"


if __name__ == "__main__":
    seconds = float(sys.argv[1])
    assert batch()  # the parent's batch: numba's threads and the helper pool at work
    pid = os.fork()
    if pid == 0:
        child()
    print("os.fork", wait(pid, seconds), flush=True)
    proc = multiprocessing.get_context("fork").Process(target=child)
    proc.start()
    proc.join(seconds)
    if proc.is_alive():
        proc.kill()
        proc.join()
        print("multiprocessing hung", flush=True)
    else:
        print("multiprocessing", proc.exitcode, flush=True)
