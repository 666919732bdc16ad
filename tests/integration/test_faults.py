"""Faults of the machine are answered like bad input: a full disk, a standard output that
cannot be written, a reader that stops reading, Ctrl-C and SIGTERM during a sweep on local
Dask workers, damaged sweep files. Each gives one line and its own exit status, leaves
nothing half-written, and a sweep resumes afterwards to the same bytes.

The full disk is a real small filesystem (a tmpfs mount) where the tests run as root and
may mount; elsewhere those tests are skipped, and the same faults are made by a write
that fails (monkeypatched to raise ENOSPC after writing part of the file)."""

from __future__ import annotations

import errno
import gc
import json
import os
import shutil
import signal
import subprocess
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

import quadcruise
from quadcruise.cli.main import main
from quadcruise.cli.montecarlo import montecarlo_command
from quadcruise.errors import InputError, WriteError
from quadcruise.io.files import MARKER, atomic_dir, atomic_path
from quadcruise.montecarlo import Population, montecarlo

SRC = str(Path(quadcruise.__file__).resolve().parents[1])  # this tree's code, in every subprocess
PWM = Path(__file__).resolve().parents[2] / "examples" / "pwm_step.csv"
SWEEP = {"seed": 3, "scheduler": "none", "chunk_size": 10, "duration": 2.0}  # 4 chunks of 10 flights
N = 40
ENOSPC = "cannot write (no space left on device)"


def quadcruise_cli(*args, cwd, timeout=300, stdout=subprocess.PIPE):
    """Run the command line of this tree's code in a new process; stderr captured, stdout too unless given."""
    env = {**os.environ, "PYTHONPATH": SRC, "QUADCRUISE_PROGRESS": "0"}
    return subprocess.run(
        [sys.executable, "-m", "quadcruise", *map(str, args)],
        stdout=stdout,
        stderr=subprocess.PIPE,
        text=True,
        cwd=cwd,
        env=env,
        timeout=timeout,
        check=False,
    )


def one_line(stderr: str) -> str:
    """The only line of ``stderr`` (it must hold exactly one, and no traceback)."""
    lines = stderr.splitlines()
    assert len(lines) == 1 and "Traceback" not in stderr, stderr
    return lines[0]


def files_under(folder: Path) -> list[str]:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


def sweep(out=None, **kw):
    return montecarlo("circle", "nlpd", Population(mass_spread=0.1), N, out=out, **{**SWEEP, **kw})


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """The sweep flown whole, untroubled: what every resumed one must equal, byte for byte."""
    out = tmp_path_factory.mktemp("reference") / "sweep"
    return sweep(out), out


def same_sweep(folder: Path, ref: Path) -> None:
    """The same flights table and chunks, byte for byte, and a complete marker."""
    assert (folder / "flights.csv").read_bytes() == (ref / "flights.csv").read_bytes()
    chunks = sorted(p.name for p in (ref / "chunks").iterdir())
    assert sorted(p.name for p in (folder / "chunks").iterdir()) == chunks
    for name in chunks:
        assert (folder / "chunks" / name).read_bytes() == (ref / "chunks" / name).read_bytes(), name
    assert json.loads((folder / MARKER).read_text())["complete"] is True


# --- a small filesystem --------------------------------------------------------------------------
@pytest.fixture
def small_disk(tmp_path):
    """``small_disk(kib)``: a tmpfs of that size mounted in tmp_path (root only), unmounted after."""
    mounted = []

    def mount(kib: int) -> Path:
        if not hasattr(os, "geteuid") or os.geteuid() != 0:
            pytest.skip(
                "a small filesystem is mounted only when the tests run as root; "
                "test_a_write_that_fails_* make the same faults without one"
            )
        point = tmp_path / f"disk{len(mounted)}"
        point.mkdir()
        proc = subprocess.run(
            ["mount", "-t", "tmpfs", "-o", f"size={kib}k", "tmpfs", str(point)],
            capture_output=True,
            text=True,
            check=False,
        )
        if proc.returncode != 0:
            pytest.skip(f"cannot mount a tmpfs here: {proc.stderr.strip() or proc.returncode}")
        mounted.append(point)
        return point

    yield mount
    for point in mounted:
        subprocess.run(["umount", "-l", str(point)], capture_output=True, check=False)


def resize(point: Path, kib: int) -> None:
    subprocess.run(["mount", "-o", f"remount,size={kib}k", str(point)], check=True)


@pytest.mark.parametrize(
    "args, target",
    [
        (["fly", "hover", "--duration", "1", "--out", "{disk}/flight"], "{disk}/flight"),
        (["replay", str(PWM), "-o", "{disk}/states.csv"], "{disk}/states.csv"),
        (["fly", "hover", "--duration", "1", "--report", "{disk}/r.html"], "{disk}/r.html"),
        (["fly", "hover", "--duration", "1", "--ulog", "{disk}/f.ulg"], "{disk}/f.ulg"),
    ],
)
def test_a_full_disk_is_one_line_exit_74_and_leaves_nothing(small_disk, tmp_path, args, target):
    disk = small_disk(8)
    proc = quadcruise_cli(*[a.format(disk=disk) for a in args], cwd=tmp_path)
    assert proc.returncode == 74
    assert one_line(proc.stderr) == f"error: {target.format(disk=disk)}: {ENOSPC}"
    assert files_under(disk) == []  # no half-written file, no temporary


def test_a_sweep_on_a_full_disk_keeps_its_chunks_and_resumes_to_the_same_bytes(small_disk, reference, tmp_path):
    _, ref_out = reference
    disk = small_disk(60)  # the marker and two chunks of 24 kB fit, not a third
    args = [
        "montecarlo",
        "--mission",
        "circle",
        "-n",
        N,
        "--seed",
        3,
        "--mass-spread",
        0.1,
        "--duration",
        2,
        "--chunk-size",
        10,
        "--scheduler",
        "none",
        "--out",
        disk / "mc",
        "--quiet",
    ]
    proc = quadcruise_cli(*args, cwd=tmp_path)
    assert proc.returncode == 74
    assert one_line(proc.stderr) == (
        f"error: {disk}/mc/chunks/chunk-000000020.npz: {ENOSPC}; the 20 flights done "
        f"are kept in {disk}/mc/chunks: the same command resumes from them"
    )
    assert files_under(disk) == [
        "mc",
        "mc/chunks",
        "mc/chunks/chunk-000000000.npz",
        "mc/chunks/chunk-000000010.npz",
        f"mc/{MARKER}",
    ]
    assert json.loads((disk / "mc" / MARKER).read_text())["complete"] is False
    resize(disk, 140)  # every chunk fits now, but not the figures
    proc = quadcruise_cli(*args, cwd=tmp_path)
    assert proc.returncode == 74 and f"all {N} flights are kept in {disk}/mc/chunks" in one_line(proc.stderr)
    assert not [p for p in (disk / "mc").rglob("*") if p.name.endswith(".tmp")]
    resize(disk, 1024)  # the fault is fixed
    proc = quadcruise_cli(*args, cwd=tmp_path)
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr
    assert f"0 flights flown ({N} resumed)" in proc.stdout
    same_sweep(disk / "mc", ref_out)


def test_a_read_only_disk_is_refused_before_any_work(small_disk, tmp_path):
    disk = small_disk(64)
    subprocess.run(["mount", "-o", "remount,ro", str(disk)], check=True)
    proc = quadcruise_cli("fly", "hover", "--duration", "1", "--out", disk / "flight", cwd=tmp_path)
    assert proc.returncode == 2 and "read-only file system" in one_line(proc.stderr)


# --- the same faults without a small filesystem: a write that fails -----------------------------
def failing_after(count: int, write):
    """``write`` that, from its ``count``-th call on, writes part of the file and then fails as a full disk does."""
    calls = []

    def fails(file, *args, **kwargs):
        calls.append(file)
        if len(calls) < count:
            return write(file, *args, **kwargs)
        if isinstance(file, (str, os.PathLike)):
            Path(file).write_bytes(b"PK\x03\x04 half")
        else:
            file.write(b"PK\x03\x04 half")
        raise OSError(errno.ENOSPC, "No space left on device")

    return fails


def test_a_write_that_fails_in_a_command_is_one_line_exit_74(tmp_path, monkeypatch):
    monkeypatch.setattr(np, "savetxt", failing_after(1, np.savetxt))
    out = tmp_path / "flight"
    result = CliRunner().invoke(main, ["fly", "hover", "--duration", "0.5", "--out", str(out)])
    assert result.exit_code == 74, result.output
    assert one_line(result.stderr) == f"error: {out}: {ENOSPC}"
    assert files_under(tmp_path) == []


def test_a_write_that_fails_in_a_sweep_keeps_its_chunks_and_it_resumes(reference, tmp_path, monkeypatch):
    ref, ref_out = reference
    out = tmp_path / "sweep"
    with monkeypatch.context() as m:
        m.setattr(np, "savez", failing_after(3, np.savez))
        with pytest.raises(WriteError) as caught:
            sweep(out)
    assert isinstance(caught.value, OSError) and caught.value.errno == errno.ENOSPC
    assert str(caught.value) == (
        f"{out}/chunks/chunk-000000020.npz: {ENOSPC}; the 20 flights done are kept in "
        f"{out}/chunks: the same command resumes from them"
    )
    assert files_under(out) == ["chunks", "chunks/chunk-000000000.npz", "chunks/chunk-000000010.npz", MARKER]
    res = sweep(out)
    assert res.info["resumed"] == 20 and res.info["flown"] == 20
    pd.testing.assert_frame_equal(res.table, ref.table, check_exact=True)
    same_sweep(out, ref_out)


def test_a_sweep_whose_folder_is_removed_meanwhile_still_writes_its_results_there(reference, tmp_path):
    ref, ref_out = reference
    out = tmp_path / "sweep"
    calls = []

    def remove_after_two_chunks(done, total):
        calls.append(done)
        if len(calls) == 3:
            shutil.rmtree(out)

    res = sweep(out, progress=remove_after_two_chunks)
    pd.testing.assert_frame_equal(res.table, ref.table, check_exact=True)
    assert (out / "flights.csv").read_bytes() == (ref_out / "flights.csv").read_bytes()
    assert sorted(p.name for p in (out / "chunks").iterdir()) == ["chunk-000000020.npz", "chunk-000000030.npz"]
    again = sweep(out)  # the two lost chunks are flown again, to the same bytes
    assert again.info["flown"] == 20 and again.info["resumed"] == 20
    same_sweep(out, ref_out)


def test_a_file_is_written_whole_or_not_at_all_and_the_error_names_it(tmp_path):
    target = tmp_path / "a" / "table.csv"
    with pytest.raises(WriteError) as caught, atomic_path(target) as tmp:
        tmp.write_text("half")
        raise OSError(errno.ENOSPC, "No space left on device")
    assert str(caught.value) == f"{target}: {ENOSPC}" and caught.value.errno == errno.ENOSPC
    assert files_under(tmp_path) == ["a"]
    folder = tmp_path / "b" / "out"
    with pytest.raises(WriteError) as caught, atomic_dir(folder) as tmp:
        (tmp / "x.csv").write_text("half")
        shutil.rmtree(folder.parent)  # its parent vanishes mid-run
        (tmp / "y.csv").write_text("lost")
    assert caught.value.filename == str(folder) and caught.value.errno == errno.ENOENT
    assert str(caught.value) == f"{folder}: cannot write (no such file or directory)"
    assert not (tmp_path / "b").exists()


def test_a_folder_replaced_is_put_back_when_the_new_one_cannot_take_its_place(tmp_path, monkeypatch):
    folder = tmp_path / "out"
    folder.mkdir()
    (folder / "old.txt").write_text("kept")
    real = os.replace

    def second_fails(src, dst):
        if Path(src).name.endswith(".tmp"):
            raise OSError(errno.EIO, "Input/output error")
        return real(src, dst)

    monkeypatch.setattr(os, "replace", second_fails)
    with pytest.raises(WriteError, match="input/output error"), atomic_dir(folder) as tmp:
        (tmp / "new.txt").write_text("new")
    assert files_under(tmp_path) == ["out", "out/old.txt"]


# --- standard output --------------------------------------------------------------------------
@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs /dev/full")
@pytest.mark.parametrize("args", [["fly", "hover", "--duration", "0.2"], ["--help"], []])
def test_a_full_standard_output_is_one_line_exit_74(tmp_path, args):
    with open("/dev/full", "w") as full:
        proc = quadcruise_cli(*args, cwd=tmp_path, stdout=full)
    assert proc.returncode == 74
    assert one_line(proc.stderr) == f"error: standard output: {ENOSPC}"


def test_a_reader_that_stops_reading_is_no_fault_and_the_folder_is_written(tmp_path):
    env = {**os.environ, "PYTHONPATH": SRC, "QUADCRUISE_PROGRESS": "0"}
    proc = subprocess.Popen(
        [sys.executable, "-m", "quadcruise", "fly", "hover", "--duration", "0.5", "--out", "f"],
        cwd=tmp_path,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    proc.stdout.close()  # as `| head -0`: every line it prints meets a broken pipe
    stderr = proc.stderr.read()
    assert proc.wait(timeout=300) == 0 and stderr == ""
    assert (tmp_path / "f" / "traces.csv").is_file() and (tmp_path / "f" / MARKER).is_file()


# --- Ctrl-C and SIGTERM during a sweep on local Dask workers -----------------------------------------
@pytest.mark.dask
@pytest.mark.slow
@pytest.mark.parametrize(
    "sig, to_group, status, word",
    [
        (signal.SIGINT, True, 130, "interrupted"),  # Ctrl-C: the terminal signals the whole group
        (signal.SIGTERM, False, 143, "terminated"),  # kill PID
    ],
)
def test_a_stopped_sweep_ends_its_workers_says_one_line_and_resumes_to_the_same_bytes(
    tmp_path, sig, to_group, status, word
):
    psutil = pytest.importorskip("psutil")
    n = 1000  # 100 chunks, 5e6 vehicle-steps: seconds of flying once the workers run, so the signal lands mid-sweep
    options = ["--mission", "circle", "-n", n, "--seed", 5, "--mass-spread", 0.1, "--duration", 5, "--chunk-size", 10]
    args = ["montecarlo", *options, "--scheduler", "local", "--workers", 2, "--out", "mc", "--quiet"]
    env = {**os.environ, "PYTHONPATH": SRC, "QUADCRUISE_PROGRESS": "0"}
    proc = subprocess.Popen(
        [sys.executable, "-m", "quadcruise", *map(str, args)],
        cwd=tmp_path,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
        preexec_fn=as_from_a_terminal,
    )
    try:
        deadline = time.monotonic() + 300
        while len(list((tmp_path / "mc" / "chunks").glob("*.npz"))) < 3:  # mid-run: chunks being written
            assert proc.poll() is None and time.monotonic() < deadline, proc.communicate()
            time.sleep(0.05)
        workers = psutil.Process(proc.pid).children(recursive=True)
        assert len(workers) >= 2
        if to_group:
            os.killpg(proc.pid, sig)
        else:
            proc.send_signal(sig)
        _, stderr = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert proc.returncode == status
    assert one_line(stderr) == f"error: {word} (a montecarlo sweep with --out resumes if run again)"
    _, alive = psutil.wait_procs(workers, timeout=30)
    assert alive == [], alive  # every worker ended with the sweep
    kept = sorted((tmp_path / "mc" / "chunks").glob("*.npz"))
    assert 3 <= len(kept) < n // 10 and not list((tmp_path / "mc").rglob("*.tmp"))
    again = quadcruise_cli(*args, cwd=tmp_path)
    assert again.returncode == 0 and again.stderr == "", again.stderr
    assert f"({len(kept) * 10:,} resumed)" in again.stdout
    montecarlo_command(
        mission="circle",
        n=n,
        seed=5,
        mass_spread=0.1,
        duration=5.0,
        chunk_size=10,
        scheduler="none",
        out=str(tmp_path / "ref"),
        quiet=True,
        echo=lambda text: None,
    )  # untroubled, in one go
    same_sweep(tmp_path / "mc", tmp_path / "ref")


def as_from_a_terminal():
    """In the child before it runs: Ctrl-C and SIGTERM act as they do for a command typed at a terminal, even when
    these tests run in the background (a shell starts a background job with SIGINT ignored, and a child keeps that)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT, signal.SIGTERM})


# --- damaged sweep files --------------------------------------------------------------------------
MARKERS = {
    "NUL-filled": (b"\0" * 2000, "NUL bytes"),
    "truncated": (None, "not JSON"),
    "a list": (b"[1, 2]\n", "a JSON array, not an object"),
    "empty": (b"", "empty"),
    "not UTF-8": (b"\xff\xfe{}", "not UTF-8 text"),
}


@pytest.mark.parametrize("kind", MARKERS)
def test_a_damaged_marker_never_costs_the_chunks(reference, tmp_path, kind):
    ref, ref_out = reference
    out = tmp_path / "sweep"
    shutil.copytree(ref_out, out)
    content, why = MARKERS[kind]
    (out / MARKER).write_bytes((ref_out / MARKER).read_bytes()[:300] if content is None else content)
    before = {p: p.read_bytes() for p in (out / "chunks").iterdir()}
    refusal = f"{out / MARKER}: damaged ({why}"
    for attempt in (
        lambda: sweep(out),
        lambda: ref.write(out),
        lambda: quadcruise.fly("hover", duration=0.2).write(out),
    ):
        with pytest.raises(InputError) as caught:
            attempt()
        assert str(caught.value).startswith(refusal) and "use --force to replace the folder, or delete it" in str(
            caught.value
        )
    assert {p: p.read_bytes() for p in (out / "chunks").iterdir()} == before
    res = sweep(out, force=True)  # the way out: forced, it is flown anew
    assert res.info["flown"] == N
    same_sweep(out, ref_out)


def test_a_damaged_marker_is_one_line_exit_2_on_the_command_line(reference, tmp_path):
    _, ref_out = reference
    shutil.copytree(ref_out, tmp_path / "mc")
    (tmp_path / "mc" / MARKER).write_bytes(b"\0" * 100)
    for args in (
        ["fly", "hover", "--duration", "0.2", "--out", "mc"],
        ["montecarlo", "-n", 4, "--mass-spread", 0.1, "--duration", 1, "--scheduler", "none", "--out", "mc"],
    ):
        proc = quadcruise_cli(*args, cwd=tmp_path)
        assert proc.returncode == 2
        assert one_line(proc.stderr).startswith("error: mc/quadcruise.json: damaged (NUL bytes)")
    assert len(list((tmp_path / "mc" / "chunks").iterdir())) == 4


def rewritten(path: Path, **change) -> None:
    """The chunk file saved again with arrays changed (a value) or removed (None)."""
    with np.load(path) as data:
        arrays = {k: data[k] for k in data.files}
    arrays.update(change)
    np.savez(path, **{k: v for k, v in arrays.items() if v is not None})


CHUNKS = {
    "NUL-filled": (lambda p: p.write_bytes(b"\0" * p.stat().st_size), "not an .npz archive"),
    "truncated": (lambda p: p.write_bytes(p.read_bytes()[:9000]), "damaged or unreadable"),
    "empty": (lambda p: p.write_bytes(b""), "not an .npz archive"),
    "without a column": (lambda p: rewritten(p, rmse_m=None), "it lacks rmse_m"),
    "with a wrong count": (lambda p: rewritten(p, count=np.int64(12)), "columns do not hold one value per flight"),
    "of another sweep": (lambda p: rewritten(p, hash=np.str_("0123456789abcdef")), "belongs to another sweep"),
    "a FIFO": (lambda p: (p.unlink(), os.mkfifo(p)), "a FIFO, not a regular file"),  # it hung the resume
}


@pytest.mark.parametrize("kind", CHUNKS)
def test_a_damaged_chunk_is_flown_again_with_a_warning_and_no_file_left_open(reference, tmp_path, kind):
    ref, ref_out = reference
    out = tmp_path / "sweep"
    shutil.copytree(ref_out, out)
    damage, words = CHUNKS[kind]
    chunk = out / "chunks" / "chunk-000000010.npz"
    damage(chunk)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = sweep(out)
        gc.collect()
    said = [str(w.message) for w in caught]
    assert [s for s in said if str(chunk) in s and words in s], said
    assert not [s for s in said if "unclosed" in s], said
    assert res.info["flown"] == 10 and res.info["resumed"] == 30
    pd.testing.assert_frame_equal(res.table, ref.table, check_exact=True)
    same_sweep(out, ref_out)


# --- issue 33: markers that are no small file, temporaries an interrupt could leave, Ctrl-C at start
@pytest.mark.parametrize(
    "make, why",
    [
        (lambda p: os.mkfifo(p), "a FIFO, not a regular file"),  # open() would wait for a writer: every command hung
        (lambda p: p.write_text("[" * 100_000 + "]" * 100_000), "not JSON: nested too deeply"),  # a RecursionError
        (lambda p: p.mkdir(), "a folder, not a regular file"),
    ],
    ids=["fifo", "nested", "folder"],
)
def test_a_marker_that_is_no_small_json_file_is_one_line_exit_2(tmp_path, make, why):
    (tmp_path / "out").mkdir()
    make(tmp_path / "out" / MARKER)
    runner = CliRunner()
    res = runner.invoke(main, ["fly", "hover", "--duration", "0.2", "--out", str(tmp_path / "out")])
    assert res.exit_code == 2 and res.exception is None or isinstance(res.exception, SystemExit), res.output
    assert f"error: {tmp_path / 'out' / MARKER}: damaged ({why})" in res.output
    with pytest.raises(InputError, match="damaged"):
        quadcruise.io.read_marker(tmp_path / "out")
    forced = runner.invoke(main, ["fly", "hover", "--duration", "0.2", "--out", str(tmp_path / "out"), "--force"])
    assert forced.exit_code == 0, forced.output  # the way out the message gives
    assert json.loads((tmp_path / "out" / MARKER).read_text())["workflow"] == "fly"


def test_a_marker_too_large_is_refused_unread(tmp_path, monkeypatch):
    import quadcruise.io.files as files

    (tmp_path / "out").mkdir()
    (tmp_path / "out" / MARKER).write_text(json.dumps({"workflow": "fly", "pad": "x" * 200}))
    assert quadcruise.io.read_marker(tmp_path / "out")["workflow"] == "fly"  # a marker within the limit is read
    monkeypatch.setattr(files, "MARKER_LIMIT", 100)
    with pytest.raises(InputError, match=r"damaged \(\d+ bytes, more than a marker's 100\)"):
        quadcruise.io.read_marker(tmp_path / "out")


def test_an_interrupt_as_a_temporary_is_made_leaves_none(tmp_path, monkeypatch):
    """Ctrl-C right after the temporary is made, before its name is returned (mkstemp's and
    mkdtemp's window), leaves nothing beside the path."""
    real_mkdir, real_open = os.mkdir, os.open

    def mkdir_then_interrupt(path, *args, **kw):
        real_mkdir(path, *args, **kw)
        if str(path).endswith(".tmp"):
            raise KeyboardInterrupt

    def open_then_interrupt(path, flags, *args, **kw):
        fd = real_open(path, flags, *args, **kw)
        if str(path).endswith(".tmp"):
            os.close(fd)
            raise KeyboardInterrupt
        return fd

    monkeypatch.setattr(os, "mkdir", mkdir_then_interrupt)
    with pytest.raises(KeyboardInterrupt), atomic_dir(tmp_path / "int"):
        pass
    monkeypatch.setattr(os, "open", open_then_interrupt)
    with pytest.raises(KeyboardInterrupt), atomic_path(tmp_path / "r.html"):
        pass
    assert files_under(tmp_path) == []


def test_an_interrupt_between_the_two_moves_of_a_folder_replaced_waits_for_the_second(tmp_path, monkeypatch):
    folder = tmp_path / "out"
    folder.mkdir()
    (folder / "old.txt").write_text("old")
    real = os.replace

    def signal_on_first(src, dst):
        if Path(dst).name == ".out.old":
            os.kill(os.getpid(), signal.SIGINT)  # Ctrl-C, between moving the old folder aside and the new one in
        return real(src, dst)

    monkeypatch.setattr(os, "replace", signal_on_first)
    with pytest.raises(KeyboardInterrupt), atomic_dir(folder) as tmp:
        (tmp / "new.txt").write_text("new")
    assert files_under(tmp_path) == ["out", "out/new.txt"]  # the new folder whole, the old one removed


@pytest.mark.parametrize("command", ["fly", "compare"])
def test_a_log_named_inside_the_out_folder_is_kept(tmp_path, command):
    """The --out folder is written first and the log into it after: it was replaced after the
    log (fly: 'wrote PX4 log', exit 0, no file; compare: its own folder refused after flying)."""
    from pyulog import ULog

    out = tmp_path / "F"
    args = ["fly", "hover"] if command == "fly" else ["compare", "hover", "--controllers", "nlpd,se3"]
    for _ in range(2):  # and again: the folder, now quadcruise's, is replaced with its logs
        res = CliRunner().invoke(main, [*args, "--duration", "0.3", "--out", str(out), "--ulog", str(out / "f.ulg")])
        assert res.exit_code == 0, res.output
        logs = sorted(out.glob("*.ulg"))
        names = ["f.ulg"] if command == "fly" else ["f-nlpd.ulg", "f-se3.ulg"]
        assert [p.name for p in logs] == names and (out / MARKER).is_file()
        assert all("wrote PX4 log" in res.output and str(p) in res.output for p in logs)
        for p in logs:
            assert ULog(str(p)).data_list  # what pyulog reads back
        assert "f.ulg" in (out / "scenario.toml").read_text() or command == "compare"


@pytest.mark.parametrize("delay", [0.1, 0.3, 3.0])
def test_ctrl_c_while_the_command_loads_is_one_line_exit_130(tmp_path, delay):
    """Ctrl-C while numba, pandas and matplotlib load (before the command runs) is the command's
    one line and status 130, not a traceback of imports; later, while it flies, the same line
    (the sweep's way on, "resumes if run again", is said for a sweep only)."""
    env = {**os.environ, "PYTHONPATH": SRC, "QUADCRUISE_PROGRESS": "0"}
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "quadcruise",
            "fly",
            "circle",
            "--duration",
            "36000",
            "--log-every",
            "1000",
            "--out",
            "out",
        ],
        cwd=tmp_path,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=as_from_a_terminal,
    )
    time.sleep(delay)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=300)
    assert proc.returncode == 130 and one_line(err) == "error: interrupted", err
    assert files_under(tmp_path) == []
    import_only = subprocess.run(  # a library user's Ctrl-C stays Python's own KeyboardInterrupt
        [sys.executable, "-c", "import signal, quadcruise; print(signal.getsignal(signal.SIGINT).__name__)"],
        env=env,
        capture_output=True,
        text=True,
        check=True,
    )
    assert import_only.stdout.strip() == "default_int_handler"


@pytest.mark.parametrize(
    "args",
    [
        ["fly", "in.csv"],
        ["fly", "in.toml"],
        ["fly", "hover", "--vehicle", "in.toml"],
        ["identify", "in.csv", "--out", "x"],
    ],
)
def test_a_fifo_given_as_an_input_file_is_one_line_not_a_wait(tmp_path, args):
    """A FIFO where a file is expected is named as such (it was 'no such file'), and nothing
    opens it: opening a FIFO waits for a writer."""
    for name in ("in.csv", "in.toml"):
        os.mkfifo(tmp_path / name)
    proc = quadcruise_cli(*args, cwd=tmp_path, timeout=120)
    assert proc.returncode == 2
    assert one_line(proc.stderr).endswith(
        "in.csv: a FIFO, not a regular file" if "in.csv" in args else "in.toml: a FIFO, not a regular file"
    )
    (tmp_path / "real.csv").write_text("x,y,z\n0,0,1\n1,0,1\n")
    assert quadcruise_cli("fly", "real.csv", "--duration", "0.2", cwd=tmp_path).returncode in (0, 1)  # a file flies
