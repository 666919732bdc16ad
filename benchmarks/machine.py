"""What every benchmark prints about the machine it ran on."""

from __future__ import annotations

import os
import platform
from pathlib import Path


def machine(**versions: str) -> dict:
    """CPU, cores, numba threads, the versions of Python, numba, numpy and quadcruise (plus
    any ``versions`` given), and the load average at the start."""
    import numba
    import numpy as np

    import quadcruise

    lines = Path("/proc/cpuinfo").read_text().splitlines() if Path("/proc/cpuinfo").exists() else []
    cpu = next((ln.split(":", 1)[1].strip() for ln in lines if ln.startswith("model name")), platform.processor())
    return {"cpu": cpu, "cores": os.cpu_count(), "numba_threads": numba.get_num_threads(),
            "python": platform.python_version(), "numba": numba.__version__, "numpy": np.__version__,
            **versions, "quadcruise": quadcruise.__version__, "load_avg_start": list(os.getloadavg())}
