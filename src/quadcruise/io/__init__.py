"""Files: atomic writes, tables on disk, strict JSON (a leaf layer: imports only ``errors``)."""

from quadcruise.io.files import (
    MARKER,
    atomic_dir,
    atomic_path,
    check_output_dir,
    check_table_format,
    check_writable_place,
    read_marker,
    read_numeric_csv,
    write_table,
)
from quadcruise.io.plainjson import dumps, plain

__all__ = [
    "MARKER",
    "atomic_dir",
    "atomic_path",
    "check_output_dir",
    "check_table_format",
    "check_writable_place",
    "dumps",
    "plain",
    "read_marker",
    "read_numeric_csv",
    "write_table",
]
