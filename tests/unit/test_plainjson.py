"""Every JSON document quadcruise writes is strict JSON (quadcruise.io.plainjson)."""

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

import quadcruise as qc
from quadcruise.io.plainjson import dumps, plain


def _strict(text):
    def refuse(name):
        raise ValueError(f"not JSON: {name}")

    return json.loads(text, parse_constant=refuse)


def test_numpy_objects_and_undefined_numbers_become_plain_values():
    @dataclass
    class Part:
        gain: float
        where: Path

    doc = {
        1: np.float32(0.5),
        "nan": math.nan,
        "inf": -np.inf,
        "arr": np.array([[1.0, np.nan]]),
        "vehicle": qc.Vehicle.paper(),
        "part": Part(np.float64(2.0), Path("a/b")),
        "ok": np.bool_(True),
    }
    got = _strict(dumps(doc))
    assert got["1"] == 0.5 and got["nan"] is None and got["inf"] is None and got["arr"] == [[1.0, None]]
    assert got["vehicle"]["m"] == qc.Vehicle.paper().m and got["part"] == {"gain": 2.0, "where": "a/b"}
    assert got["ok"] is True
    with pytest.raises(TypeError, match="cannot record object"):
        plain({"x": object()})


def test_a_result_bundle_records_null_not_nan():
    res = qc.fly("hover", "nlpd", duration=0.5)
    res.meta["note"] = float("nan")  # a record with an undefined number in it
    assert _strict(res.meta_json())["note"] is None
