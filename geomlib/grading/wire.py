"""A pickle-free, bounded format for values crossing from student code to the grader.

Unpickling data from untrusted code can run arbitrary code in the grader, so results come back as
JSON (structure) plus raw array buffers whose dtype and shape the JSON names. Nothing is
compressed, so a message is never larger once read than on the wire, and :func:`decode` checks
every size against ``max_bytes`` *before* it allocates. Supported: None, bool, int, float, str,
tuples, lists, dicts with string keys, NumPy arrays and scalars (numbers and booleans), SciPy sparse
matrices and dataclasses (decoded as :class:`ReturnedDataclass`).

Layout: ``b"GW1"``, the JSON length (``<Q``), the JSON, then the array buffers back to back.
"""

from __future__ import annotations

import dataclasses
import json
import math
import struct

import numpy as np

__all__ = ["encode", "decode", "ReturnedDataclass", "WireError", "MAGIC"]

MAGIC = b"GW1"
_MAX_DEPTH = 20
_MAX_ITEMS = 100_000  # JSON nodes (list items, dict entries) in one message
_DTYPES = {"b1", "i1", "i2", "i4", "i8", "u1", "u2", "u4", "u8", "f2", "f4", "f8", "c8", "c16"}


class WireError(TypeError):
    """A value that cannot cross the wire; the message names the offending type or size."""


class ReturnedDataclass:
    """Attribute access to the fields of a dataclass returned by student code (its class stays behind)."""

    def __init__(self, type_name: str, fields: dict):
        self._type_name = type_name
        self.__dict__.update(fields)

    def __repr__(self) -> str:
        keys = ", ".join(k for k in self.__dict__ if not k.startswith("_"))
        return f"{self._type_name}({keys})"


def encode(value) -> bytes:
    """The bytes of ``value`` (raises :class:`WireError` naming what cannot be sent)."""
    arrays: list[np.ndarray] = []

    def array(a: np.ndarray) -> dict:
        a = np.ascontiguousarray(a)
        if a.dtype.kind not in "biufc":
            raise WireError(f"an array of dtype {a.dtype} (expected numbers or booleans)")
        a = a.astype(a.dtype.newbyteorder("<"), copy=False)
        arrays.append(a)
        return {"__nd__": len(arrays) - 1, "dtype": a.dtype.str.lstrip("<|="), "shape": [int(s) for s in a.shape]}

    def enc(o, depth=0):
        if depth > _MAX_DEPTH:
            raise WireError("the returned value is nested too deeply")
        if o is None or isinstance(o, bool | str):
            return o
        if isinstance(o, int):
            return o if abs(o) < 2**53 else {"__float__": float(o)}
        if isinstance(o, float):
            return o if math.isfinite(o) else {"__float__": repr(o)}
        if isinstance(o, complex):
            return {"__complex__": [repr(o.real), repr(o.imag)]}
        if isinstance(o, np.generic):
            if o.dtype.kind not in "biufc":
                raise WireError(f"a NumPy scalar of dtype {o.dtype}")
            return enc(o.item(), depth + 1)
        if isinstance(o, np.ndarray):
            return array(o)
        if hasattr(o, "tocoo") and hasattr(o, "shape") and hasattr(o, "nnz"):
            c = o.tocoo()
            return {"__sparse__": [array(c.row), array(c.col), array(c.data)], "shape": [int(s) for s in c.shape]}
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

    meta = json.dumps(enc(value), ensure_ascii=True).encode()
    return b"".join([MAGIC, struct.pack("<Q", len(meta)), meta, *(a.tobytes() for a in arrays)])


def decode(data: bytes, *, max_bytes: int | None = None, max_dense_elements: int | None = None):
    """The value encoded in ``data``; raises :class:`WireError` on malformed or oversized data.

    Parameters
    ----------
    max_bytes : int, optional
        Largest total size of the arrays (and of the JSON) accepted.
    max_dense_elements : int, optional
        Largest ``rows * cols`` of a sparse matrix (checks densify small matrices; a forged shape
        must not make them allocate terabytes).
    """
    if data[:3] != MAGIC or len(data) < 11:
        raise WireError("malformed message (bad header)")
    (n,) = struct.unpack("<Q", data[3:11])
    if n > len(data) - 11 or (max_bytes is not None and n > max_bytes):
        raise WireError(f"malformed message (structure of {n} bytes)")
    try:
        meta = json.loads(data[11 : 11 + n].decode("ascii"))
    except (UnicodeDecodeError, ValueError, RecursionError):
        raise WireError("malformed message (structure is not JSON)") from None
    body = memoryview(data)[11 + n :]
    offset = 0
    items = 0

    def nd(o) -> np.ndarray:
        nonlocal offset
        dtype, shape = o.get("dtype"), o.get("shape")
        if dtype not in _DTYPES or not isinstance(shape, list) or len(shape) > 32:
            raise WireError("malformed message (array header)")
        if not all(isinstance(s, int) and not isinstance(s, bool) and 0 <= s < 2**48 for s in shape):
            raise WireError("malformed message (array shape)")
        dt = np.dtype("<" + dtype if dtype != "b1" else "?")
        count = math.prod(shape)
        size = count * dt.itemsize
        if max_bytes is not None and offset + size > max_bytes:
            raise WireError(
                f"an array of shape {tuple(shape)}, more data than this call may return ({max_bytes >> 20} MiB)"
            )
        if offset + size > len(body):
            raise WireError("malformed message (array data cut short)")
        a = np.frombuffer(body, dtype=dt, count=count, offset=offset).reshape(shape).copy()
        offset += size
        return a

    def dec(o, depth=0):
        nonlocal items
        items += 1
        if depth > _MAX_DEPTH + 2 or items > _MAX_ITEMS:
            raise WireError("the returned value is nested too deeply or has too many items")
        if isinstance(o, list):
            return [dec(x, depth + 1) for x in o]
        if not isinstance(o, dict):
            return o
        if "__nd__" in o:
            return nd(o)
        if "__float__" in o:
            return float(o["__float__"])
        if "__complex__" in o:
            re_, im = o["__complex__"]
            return complex(float(re_), float(im))
        if "__tuple__" in o:
            return tuple(dec(x, depth + 1) for x in o["__tuple__"])
        if "__dict__" in o:
            return {str(k): dec(v, depth + 1) for k, v in o["__dict__"].items()}
        if "__sparse__" in o:
            import scipy.sparse as sp

            shape = o.get("shape")
            if not (
                isinstance(shape, list)
                and len(shape) == 2
                and all(isinstance(s, int) and 0 <= s < 2**31 for s in shape)
            ):
                raise WireError("malformed message (sparse shape)")
            if max_dense_elements is not None and shape[0] * shape[1] > max_dense_elements:
                raise WireError(f"a sparse matrix of shape {tuple(shape)}, far larger than this call's inputs allow")
            r, c, d = (nd(x) for x in o["__sparse__"])
            if not (r.ndim == c.ndim == d.ndim == 1 and len(r) == len(c) == len(d)):
                raise WireError("malformed message (sparse triplets)")
            if r.dtype.kind not in "iu" or c.dtype.kind not in "iu":
                raise WireError("a sparse matrix with non-integer indices")
            if len(r) and (r.min() < 0 or r.max() >= shape[0] or c.min() < 0 or c.max() >= shape[1]):
                raise WireError("a sparse matrix with indices outside its shape")
            return sp.csr_matrix((d, (r, c)), shape=tuple(shape))
        if "__record__" in o:
            return ReturnedDataclass(
                str(o["__record__"])[:200], {str(k): dec(v, depth + 1) for k, v in o["fields"].items()}
            )
        raise WireError("malformed message (unknown node)")

    try:
        return dec(meta)
    except WireError:
        raise
    except (TypeError, ValueError, KeyError, AttributeError, OverflowError, MemoryError) as e:
        raise WireError(f"malformed message ({type(e).__name__})") from None
