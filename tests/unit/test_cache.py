"""numba's cache is dropped when any of the package's sources changes (quadcruise._cache)."""

import hashlib
import os
import subprocess
import sys

from quadcruise._cache import PACKAGE, STAMP, cache_dirs, drop_stale_cache, sources_stamp


def test_cache_files_go_when_any_source_changes(tmp_path):
    pkg = tmp_path / "pkg"
    (pkg / "model" / "__pycache__").mkdir(parents=True)
    (pkg / "engine.py").write_text("import numba\nx = 1\n")
    (pkg / "model" / "plant.py").write_text("from numba import njit\ny = 2\n")
    (pkg / "tables.py").write_text("z = 3\n")
    cached = [
        pkg / "model" / "__pycache__" / "plant.derivative-1.py311.nbi",
        pkg / "model" / "__pycache__" / "plant.derivative-1.py311.1.nbc",
    ]
    for path in cached:
        path.write_bytes(b"machine code")
    assert drop_stale_cache(pkg, "")  # no stamp yet: dropped
    assert not any(p.exists() for p in cached)
    for path in cached:
        path.write_bytes(b"machine code")
    assert not drop_stale_cache(pkg, "")  # unchanged sources: kept
    assert all(p.exists() for p in cached)
    before = sources_stamp(pkg)
    (pkg / "tables.py").write_text("z = 4\n")  # no compiled code in it: the cache stays
    assert sources_stamp(pkg) == before and not drop_stale_cache(pkg, "")
    plant = pkg / "model" / "plant.py"
    st = plant.stat()
    os.utime(plant, ns=(st.st_atime_ns, st.st_mtime_ns + 10**9))  # touched, not changed: stays
    assert sources_stamp(pkg) == before
    plant.write_text("from numba import njit\ny = 3\n")  # an edit to a callee's file only
    assert sources_stamp(pkg) != before
    assert drop_stale_cache(pkg, "") and not any(p.exists() for p in cached)
    (pkg / "new.py").write_text("import numba\n")  # a new compiled module changes the stamp too
    assert drop_stale_cache(pkg, "") and not drop_stale_cache(pkg, "")


def test_a_numba_cache_dir_is_cleaned_too(tmp_path):
    """With NUMBA_CACHE_DIR set, numba keeps a source folder's code in
    <dir>/<folder name>_<sha1 of the folder's path>; that is where stale files go from."""
    pkg = tmp_path / "pkg"
    pkg.mkdir()
    (pkg / "engine.py").write_text("import numba\n")
    where = tmp_path / "nc" / f"pkg_{hashlib.sha1(str(pkg).encode()).hexdigest()}"
    where.mkdir(parents=True)
    stale = where / "engine._kernel-1.py311.nbi"
    stale.write_bytes(b"machine code")
    assert drop_stale_cache(pkg, str(tmp_path / "nc")) and not stale.exists()
    stale.write_bytes(b"machine code")
    assert not drop_stale_cache(pkg, str(tmp_path / "nc")) and stale.exists()
    (pkg / "engine.py").write_text("import numba\nx = 1\n")
    assert drop_stale_cache(pkg, str(tmp_path / "nc")) and not stale.exists()


def _python(code: str, cache_dir) -> str:
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache_dir))
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    return out.stdout.strip()


def test_import_quadcruise_loads_no_numba_and_deletes_nothing_until_compiled_code_loads(tmp_path):
    stale = cache_dirs(PACKAGE, str(tmp_path))[0] / "engine._kernel-1.py311.nbi"
    stale.parent.mkdir(parents=True)
    stale.write_bytes(b"machine code of other sources")  # no stamp beside it: stale
    loaded = _python(
        "import sys, quadcruise\n"
        "print(sorted(m for m in sys.modules if m.split('.')[0] in ('numba', 'llvmlite', 'quadcruise')))",
        tmp_path,
    )
    assert loaded == str(["quadcruise", "quadcruise._cache", "quadcruise._version", "quadcruise.errors"])
    assert stale.exists()  # import quadcruise deleted nothing
    _python("import quadcruise.layout", tmp_path)  # the first module that may hold compiled code
    assert not stale.exists() and (stale.parent / STAMP).read_text() == sources_stamp(PACKAGE)
