"""A pickle-free format for values crossing from student code to the grader.

Unpickling data from untrusted code can run arbitrary code in the grader, so results come back as
JSON (structure) plus an ``.npz`` (arrays, loaded with ``allow_pickle=False``). Supported: None,
bool, int, float, str, tuples, lists, dicts with string keys, NumPy arrays and scalars, SciPy
sparse matrices and dataclasses (decoded as :class:`Record`).
"""

from __future__ import annotations

import dataclasses
import io
import json
import math
import struct

import numpy as np

__all__ = ["encode", "decode", "Record", "WireError"]

_MAX_DEPTH = 20


class WireError(TypeError):
    """A value that cannot be sent back to the grader; the message names the offending type."""


class Record:
    """Attribute access to the fields of a dataclass returned by student code."""

    def __init__(self, type_name: str, fields: dict):
        self._type_name = type_name
        self.__dict__.update(fields)

    def __repr__(self) -> str:
        keys = ", ".join(k for k in self.__dict__ if not k.startswith("_"))
        return f"{self._type_name}({keys})"


def encode(value) -> bytes:
    arrays: list[np.ndarray] = []

    def enc(o, depth=0):
        if depth > _MAX_DEPTH:
            raise WireError("the returned value is nested too deeply")
        if o is None or isinstance(o, bool | str):
            return o
        if isinstance(o, int):
            return o if abs(o) < 2**53 else {"__float__": float(o)}
        if isinstance(o, float):
            return o if math.isfinite(o) else {"__float__": repr(o)}
        if isinstance(o, np.generic):
            return enc(o.item(), depth + 1)
        if isinstance(o, np.ndarray):
            if o.dtype.kind not in "biufc":
                raise WireError(f"an array of dtype {o.dtype} (expected numbers or booleans)")
            arrays.append(np.ascontiguousarray(o))
            return {"__nd__": len(arrays) - 1}
        if hasattr(o, "tocoo") and hasattr(o, "shape") and hasattr(o, "nnz"):
            c = o.tocoo()
            return {"__sparse__": [enc(c.row), enc(c.col), enc(c.data)], "shape": [int(s) for s in c.shape]}
        if isinstance(o, tuple):
            return {"__tuple__": [enc(x, depth + 1) for x in o]}
        if isinstance(o, list):
            return [enc(x, depth + 1) for x in o]
        if isinstance(o, dict):
            if not all(isinstance(k, str) for k in o):
                raise WireError("a dict with non-string keys")
            return {"__dict__": {k: enc(v, depth + 1) for k, v in o.items()}}
        if dataclasses.is_dataclass(o) and not isinstance(o, type):
            fields = {f.name: enc(getattr(o, f.name), depth + 1) for f in dataclasses.fields(o)}
            return {"__record__": type(o).__name__, "fields": fields}
        raise WireError(f"an object of type {type(o).__module__}.{type(o).__qualname__}")

    meta = json.dumps(enc(value)).encode()
    buf = io.BytesIO()
    np.savez(buf, *arrays)
    return struct.pack("<Q", len(meta)) + meta + buf.getvalue()


def decode(data: bytes):
    (n,) = struct.unpack("<Q", data[:8])
    meta = json.loads(data[8 : 8 + n].decode())
    with np.load(io.BytesIO(data[8 + n :]), allow_pickle=False) as z:
        arrays = [z[f"arr_{i}"] for i in range(len(z.files))]

    def dec(o):
        if isinstance(o, list):
            return [dec(x) for x in o]
        if not isinstance(o, dict):
            return o
        if "__nd__" in o:
            return arrays[o["__nd__"]]
        if "__float__" in o:
            return float(o["__float__"])
        if "__tuple__" in o:
            return tuple(dec(x) for x in o["__tuple__"])
        if "__dict__" in o:
            return {k: dec(v) for k, v in o["__dict__"].items()}
        if "__sparse__" in o:
            import scipy.sparse as sp

            r, c, d = (dec(x) for x in o["__sparse__"])
            return sp.csr_matrix((d, (r, c)), shape=tuple(o["shape"]))
        if "__record__" in o:
            return Record(o["__record__"], {k: dec(v) for k, v in o["fields"].items()})
        raise WireError("malformed message from the worker")

    return dec(meta)
