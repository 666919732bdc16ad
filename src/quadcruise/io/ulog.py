"""PX4's ULog file format, written: the definitions, then every topic's samples in time order.

The layout follows PX4's ``dev/log/ulog_file_format``; a topic's samples are one numpy structured
array, so a flight of any length is written without a Python loop over its samples (a format's
trailing ``_padding`` field is declared but, as PX4 writes it, not sent).

Examples
--------
>>> import tempfile, numpy as np
>>> from pathlib import Path
>>> from pyulog import ULog
>>> topic = Topic("vehicle_angular_velocity",
...               (("uint64_t", 0, "timestamp"), ("float", 3, "xyz")),
...               {"timestamp": np.array([1000, 2000]), "xyz": np.zeros((2, 3))})
>>> with tempfile.TemporaryDirectory() as folder:
...     write_ulog(Path(folder) / "a.ulg", [topic], info={"sys_name": "quadcruise"})
...     log = ULog(str(Path(folder) / "a.ulg"))
>>> log.get_dataset("vehicle_angular_velocity").data["timestamp"].tolist()
[1000, 2000]
"""

from __future__ import annotations

import os
import struct
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from quadcruise.io.files import atomic_path

MAGIC = b"ULog\x01\x12\x35"
"""The first seven bytes of every ULog file."""

NUMPY_TYPES = {
    "int8_t": "i1",
    "uint8_t": "u1",
    "bool": "u1",
    "char": "S1",
    "int16_t": "<i2",
    "uint16_t": "<u2",
    "int32_t": "<i4",
    "uint32_t": "<u4",
    "int64_t": "<i8",
    "uint64_t": "<u8",
    "float": "<f4",
    "double": "<f8",
}
"""ULog's field types and the little-endian numpy types they are packed as."""


@dataclass(frozen=True)
class Topic:
    """One topic: its ``name``, its ``fields`` as PX4 orders them (ULog type, array length or 0, name;
    ``uint64_t timestamp`` [us] first) and each field's ``values`` (a field not given is zeros).
    A field whose type is a key of ``nested`` is a nested message of those fields (written whole,
    its padding included); its values are given as ``"field.subfield"``.
    """

    name: str
    fields: Sequence[tuple[str, int, str]]
    values: Mapping[str, np.ndarray]
    nested: Mapping[str, Sequence[tuple[str, int, str]]] = field(default_factory=dict)

    def _dtype(self, kind: str):
        if kind in self.nested:
            return np.dtype(
                [(name, self._dtype(k), (length,) if length else ()) for k, length, name in self.nested[kind]]
            )
        return NUMPY_TYPES[kind]

    def records(self, msg_id: int) -> np.ndarray:
        """The topic's data messages under ``msg_id``, headers included, as one packed structured array."""
        if not self.fields or self.fields[0][2] != "timestamp":
            raise ValueError(f"topic {self.name!r}: the first field must be the timestamp")
        packed = self.fields[:-1] if self.fields[-1][2].startswith("_padding") else self.fields  # as PX4 does
        fields = [(name, self._dtype(kind), (length,) if length else ()) for kind, length, name in packed]
        dtype = np.dtype([("size", "<u2"), ("type", "u1"), ("msg_id", "<u2"), *fields])
        n = len(self.values["timestamp"])
        out = np.zeros(n, dtype)
        out["size"] = dtype.itemsize - 3
        out["type"] = ord("D")
        out["msg_id"] = msg_id
        for name, value in self.values.items():
            outer, _, inner = name.partition(".")
            if outer not in dtype.names or (inner and inner not in (dtype[outer].base.names or ())):
                raise ValueError(f"topic {self.name!r} has no field {name!r}")
            if inner:
                out[outer][inner] = value
            else:
                out[name] = value
        return out

    def format_message(self) -> bytes:
        """The topic's format message payload, ``name:type field;...``."""
        text = "".join(
            f"{kind}[{length}] {name};" if length else f"{kind} {name};" for kind, length, name in self.fields
        )
        return f"{self.name}:{text}".encode()


def _message(kind: str, payload: bytes) -> bytes:
    return struct.pack("<HB", len(payload), ord(kind)) + payload


def _key_value(kind: str, name: str, value) -> bytes:
    if isinstance(value, str):
        data, type_name = value.encode(), f"char[{len(value.encode())}]"
    elif isinstance(value, (int, np.integer)) and not isinstance(value, bool):
        data, type_name = struct.pack("<i", int(value)), "int32_t"
    else:
        data, type_name = struct.pack("<f", float(value)), "float"
    key = f"{type_name} {name}".encode()
    return _message(kind, struct.pack("<B", len(key)) + key + data)


def ulog_bytes(
    topics: Sequence[Topic],
    *,
    info: Mapping[str, object] | None = None,
    parameters: Mapping[str, float | int] | None = None,
    start_us: int = 0,
) -> bytes:
    """A whole ULog file's bytes: each topic under its own id, ``info`` and ``parameters`` messages
    (str, int32 or float), the header's ``start_us`` [us].
    """
    head = [MAGIC + b"\x01" + struct.pack("<Q", start_us), _message("B", bytes(16) + struct.pack("<QQQ", 0, 0, 0))]
    nested = {kind: fields for topic in topics for kind, fields in topic.nested.items()}
    head += [_message("F", Topic(kind, fields, {}).format_message()) for kind, fields in nested.items()]
    head += [_message("F", topic.format_message()) for topic in topics]
    head += [_key_value("I", name, value) for name, value in (info or {}).items()]
    head += [_key_value("P", name, value) for name, value in (parameters or {}).items()]
    head += [_message("A", struct.pack("<BH", 0, msg_id) + topic.name.encode()) for msg_id, topic in enumerate(topics)]

    records = [topic.records(msg_id) for msg_id, topic in enumerate(topics)]
    stamps = np.concatenate([r["timestamp"] for r in records])
    sizes = np.concatenate([np.full(len(r), r.dtype.itemsize) for r in records])
    order = np.argsort(stamps, kind="stable")  # time order; ties keep the topic order
    offsets = np.empty(len(order), np.int64)
    offsets[order] = np.concatenate([[0], np.cumsum(sizes[order])[:-1]]) if len(order) else []
    body = np.empty(int(sizes.sum()), np.uint8)
    first = 0
    for r in records:
        rows = r.view(np.uint8).reshape(len(r), r.dtype.itemsize)
        where = offsets[first : first + len(r), None] + np.arange(r.dtype.itemsize)
        body[where] = rows
        first += len(r)
    return b"".join(head) + body.tobytes()


def write_ulog(path: str | os.PathLike, topics: Sequence[Topic], **kwargs) -> None:
    """Write a ULog file whole or not at all (``**kwargs``: those of :func:`ulog_bytes`)."""
    data = ulog_bytes(topics, **kwargs)
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)
