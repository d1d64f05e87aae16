"""Shared pieces of the mesh readers and writers: sources for error messages, files as line
blocks parsed by NumPy, face lists to write."""

from __future__ import annotations

import os
import re
import stat
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from geomlib import topology
from geomlib.validate import MeshError, as_array, as_vertices, check_int

PathLike = str | os.PathLike
Faces = np.ndarray | list[np.ndarray]

MESH_EXTENSIONS = (".obj", ".off", ".ply")


# --------------------------------------------------------------------------------------------
# Shared helpers
# --------------------------------------------------------------------------------------------


class _Source:
    """Where we are reading from, for error messages: ``"where: path, line N: problem"``."""

    def __init__(self, where: str, path: PathLike):
        self.where = where
        self.path = str(path)

    def error(self, msg: str, line: int | None = None) -> MeshError:
        loc = f"{self.path}, line {line}" if line is not None else self.path
        return MeshError(f"{self.where}: {loc}: {msg}")


def _read_bytes(path: PathLike, where: str) -> bytes:
    check_regular_file(path, where)
    with open(path, "rb") as fh:
        return fh.read()


def check_regular_file(path: PathLike, where: str, what: str = "a mesh file") -> None:
    """Raise FileNotFoundError for a missing file and MeshError for a folder, FIFO, socket or device.

    Opening a FIFO would block until someone writes to it, and a folder gives a bare
    IsADirectoryError: both are caught before ``open``.
    """
    st = os.stat(path)  # FileNotFoundError names the path
    if stat.S_ISDIR(st.st_mode):
        raise MeshError(f"{where}: {path} is a folder; give {what}")
    if not stat.S_ISREG(st.st_mode):
        kind = "a FIFO (named pipe)" if stat.S_ISFIFO(st.st_mode) else "not a regular file"
        raise MeshError(f"{where}: {path} is {kind}; give {what}")


def _ext(path: PathLike) -> str:
    return Path(path).suffix.lower()


# Bytes that bytes.split() treats as whitespace.
_WS = np.zeros(256, dtype=bool)
_WS[[9, 10, 11, 12, 13, 32]] = True


def _token_layout(joined: bytes, n_lines: int, *, token_ids: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Token structure of ``n_lines`` lines joined by ``b"\\n"``, computed without Python loops.

    Returns ``(counts, byte_view, token_id)``: tokens per line ``(n_lines,)``, the bytes as uint8,
    and for every byte the index of the token it belongs to (or the previous token for whitespace).
    """
    b = np.frombuffer(joined, dtype=np.uint8)
    if b.size == 0:
        return np.zeros(n_lines, np.int64), b, np.zeros(0, np.int64)
    ws = _WS[b]
    start = ~ws
    start[1:] &= ws[:-1]
    # Tokens per line: count token starts between consecutive newlines.
    nl = np.flatnonzero(b == 10)
    cs = np.concatenate([[0], np.cumsum(start, dtype=np.int64)])
    bounds = np.concatenate([[0], nl, [len(b)]])[: n_lines + 1]
    if len(bounds) < n_lines + 1:
        bounds = np.concatenate([bounds, np.full(n_lines + 1 - len(bounds), len(b))])
    counts = np.diff(cs[bounds])
    token_id = cs[1:] - 1 if token_ids else np.zeros(0, np.int64)
    return counts, b, token_id


def _fromstring(text: bytes, dtype) -> np.ndarray | None:
    """Whitespace-separated numbers parsed in C; None if some token is not a number."""
    with warnings.catch_warnings():
        # NumPy < 2.3 only warns (DeprecationWarning) when a token does not parse, and returns the
        # numbers read so far: "2.5" read as int64 gives 2 and stops. Treat the warning as the error
        # that newer NumPy raises.
        warnings.simplefilter("error", DeprecationWarning)
        try:
            return np.fromstring(text, dtype=dtype, sep=" ")
        except (ValueError, DeprecationWarning):
            return None


def _take_columns(data: np.ndarray, counts: np.ndarray, ncols: int, fill: float = 0.0) -> np.ndarray:
    """First ``ncols`` numbers of every line (``fill`` where a line has fewer), ``(n_lines, ncols)``."""
    starts = np.cumsum(counts) - counts
    cols = np.arange(ncols)
    idx = starts[:, None] + cols
    have = cols < counts[:, None]
    if data.size == 0:
        return np.full((len(counts), ncols), fill, dtype=data.dtype)
    return np.where(have, data[np.minimum(idx, data.size - 1)], fill)


_COMMENT = re.compile(rb"#[^\n]*")
_LEADING_WS = re.compile(rb"(?m)^[ \t]+")


@dataclass
class _Rows:
    """Some lines of a text file joined by ``b"\\n"``, with their 1-based line numbers."""

    text: bytes
    lines: np.ndarray

    def __len__(self) -> int:
        return len(self.lines)

    def split(self) -> list[bytes]:
        return self.text.split(b"\n")[: len(self.lines)]

    def subset(self, sel: np.ndarray) -> _Rows:
        rows = self.split()
        idx = np.flatnonzero(sel)
        return _Rows(b"\n".join([rows[i] for i in idx.tolist()]), self.lines[idx])


class _TextFile:
    """A text file as bytes, cut into lines with NumPy so no Python code runs per line.

    ``strip_comments`` removes ``#`` comments (OBJ, OFF); line numbers are unchanged.
    """

    def __init__(self, data: bytes, *, strip_comments: bool = False, first_line: int = 1):
        if strip_comments and b"#" in data:
            data = _COMMENT.sub(b"", data)
        self.data = data
        self.first_line = first_line
        self.b = np.frombuffer(data, dtype=np.uint8)
        self.starts = np.concatenate([[0], np.flatnonzero(self.b == 10) + 1]).astype(np.int64)
        self.n = len(self.starts)
        self.lengths = np.diff(self.starts, append=len(self.b))  # including the newline

    def line_number(self, i) -> np.ndarray:
        return np.asarray(i, dtype=np.int64) + self.first_line

    def nonblank(self) -> np.ndarray:
        """Indices of lines holding something other than whitespace."""
        cs = np.concatenate([[0], np.cumsum(~_WS[self.b], dtype=np.int32 if len(self.b) < 2**31 - 1 else np.int64)])
        return np.flatnonzero(cs[self.starts + self.lengths] > cs[self.starts])

    def head(self, k: int) -> np.ndarray:
        """First ``k`` bytes of every line, ``(n, k)`` uint8, zero past the end of the file."""
        pad = np.zeros(len(self.b) + k + 1, dtype=np.uint8)
        pad[: len(self.b)] = self.b
        return pad[self.starts[:, None] + np.arange(k)]

    def line(self, i: int) -> bytes:
        return self.data[self.starts[i] : self.starts[i] + self.lengths[i]].rstrip(b"\n")

    def rows(self, lines: np.ndarray, skip: int = 0) -> _Rows:
        """The given lines (sorted indices) without their first ``skip`` bytes."""
        lines = np.asarray(lines, dtype=np.int64)
        if len(lines) == 0:
            return _Rows(b"", lines + self.first_line)
        flag = np.zeros(self.n, dtype=bool)
        flag[lines] = True
        keep = np.repeat(flag, self.lengths)
        if skip:
            drop = self.starts[lines][:, None] + np.arange(skip)
            keep[drop[drop < len(keep)]] = False
        return _Rows(self.b[keep].tobytes(), lines + self.first_line)


def _parse_float_lines(
    src: _Source, rows: _Rows, *, what: str, minimum: int, try_int: bool = False
) -> tuple[np.ndarray, np.ndarray]:
    """Parse lines of numbers; every line needs at least ``minimum`` of them.

    Returns ``(data, counts)``: all numbers in file order (float64, or int64 when ``try_int`` and
    every token is an integer, which parses about three times faster) and the count per line.
    """
    n = len(rows)
    if n == 0:
        return np.zeros(0), np.zeros(0, np.int64)
    counts, _, _ = _token_layout(rows.text, n)
    short = counts < minimum
    if short.any():
        i = int(np.flatnonzero(short)[0])
        raise src.error(f"expected {minimum} {what}, got {int(counts[i])}", int(rows.lines[i]))
    data = _fromstring(rows.text, np.int64) if try_int else None
    if data is None or data.size != counts.sum():
        data = _fromstring(rows.text, np.float64)
    if data is None or data.size != counts.sum():
        # Locate the offending token (and, if Python reads what NumPy refused, keep its values).
        vals = []
        for rest, ln in zip(rows.split(), rows.lines.tolist(), strict=True):
            for tok in rest.split():
                try:
                    vals.append(float(tok))
                except ValueError:
                    raise src.error(f"cannot read number '{tok.decode('latin-1')}' in {what}", ln) from None
        data = np.array(vals, dtype=np.float64)
    return data, counts


def _check_finite_rows(src: _Source, A: np.ndarray, line_nums: np.ndarray | None, what: str) -> None:
    bad = ~np.isfinite(A).all(axis=1)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        vals = ", ".join(f"{x:.6g}" for x in A[i])
        if line_nums is None:
            raise src.error(f"{what} {i} has a non-finite value ({vals})")
        raise src.error(f"{what} has a non-finite value ({vals})", int(line_nums[i]))


def _ragged_to_faces(idx: np.ndarray, off: np.ndarray) -> Faces:
    """``(indices, offsets)`` -> ``(m, k)`` array when all faces have k corners, else a list."""
    lens = np.diff(off)
    if len(lens) == 0:
        return np.zeros((0, 3), dtype=np.int64)
    if (lens == lens[0]).all():
        return idx.reshape(len(lens), int(lens[0]))
    return np.split(idx, off[1:-1])


def _triangulate(idx: np.ndarray, off: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Fan triangles and the corner position each triangle corner came from."""
    corners = np.arange(len(idx), dtype=np.int64)
    C, _ = topology.triangulate_polygons((corners, off))
    return idx[C] if C.size else np.zeros((0, 3), np.int64), C


def _faces_for_writing(F, n: int, *, name: str, where: str, target: str = "V") -> tuple[np.ndarray, np.ndarray]:
    """Validate faces to write (``(m, k)`` array or list of polygons); return ragged ``(indices, offsets)``.

    ``target`` is the array the indices point into (``V``, ``UV`` or ``N``). Repeated indices are
    allowed: attribute faces repeat them routinely (one flat normal for a whole face).
    """
    if F is None:
        raise MeshError(f"{where}: {name} is missing (got None)")
    arr = None
    if isinstance(F, np.ndarray) and F.dtype != object:
        arr = F
    else:
        try:
            a = np.asarray(F)
            if a.dtype != object and a.ndim == 2:
                arr = a
        except ValueError:  # ragged list
            pass
    if arr is not None:
        if arr.ndim == 2 and arr.shape[0] == 0:
            return np.zeros(0, np.int64), np.zeros(1, np.int64)
        arr = as_array(arr, name, shape=(None, None), dtype=np.int64, where=where)
        m, k = arr.shape
        idx, lens = arr.ravel(), np.full(m, k, dtype=np.int64)
    else:
        if isinstance(F, str | bytes) or not hasattr(F, "__iter__"):
            raise MeshError(f"{where}: {name} must be an (m, k) integer array or a list of index sequences")
        polys = []
        for i, f in enumerate(F):
            try:
                a = np.asarray(f)
            except ValueError:
                a = None
            if a is None or a.ndim != 1:
                raise MeshError(f"{where}: {name}: face {i} is not a flat sequence of indices")
            polys.append(a)
        lens = np.array([len(a) for a in polys], dtype=np.int64)
        flat = np.concatenate(polys) if polys else np.zeros(0, np.int64)
        idx = as_array(flat, name, shape=(None,), dtype=np.int64, where=where)
    if len(lens) and lens.min() < 3:
        f = int(np.flatnonzero(lens < 3)[0])
        raise MeshError(f"{where}: {name}: face {f} has {int(lens[f])} vertices; a face needs at least 3")
    off = np.concatenate([[0], np.cumsum(lens)]).astype(np.int64)
    bad = (idx < 0) | (idx >= n)
    if bad.any():
        j = int(np.flatnonzero(bad)[0])
        f = int(np.searchsorted(off, j, side="right") - 1)
        v = int(idx[j])
        what = (
            f"vertex {v}, but V has only {n} vertices"
            if target == "V"
            else f"{target} row {v}, but {target} has only {n} rows"
        )
        raise MeshError(f"{where}: {name}: face {f} uses {what} (valid indices 0..{n - 1})")
    return idx, off


def _writer_inputs(V, F, precision: int | None, where: str, *, faces_optional: bool = False):
    """What every writer checks first: ``(V, indices, offsets, precision)``, faces as ragged lists.

    ``F=None`` is an error unless ``faces_optional`` (a PLY point cloud: no faces).
    """
    V = as_vertices(V, where=where)
    if F is None and faces_optional:
        idx, off = np.zeros(0, np.int64), np.zeros(1, np.int64)
    else:
        idx, off = _faces_for_writing(F, len(V), name="F", where=where)
    if precision is not None:
        precision = check_int(precision, "precision", minimum=1, maximum=17, where=where)
    return V, idx, off, precision


def _counted_face_lines(idx: np.ndarray, off: np.ndarray) -> str:
    """Faces as text lines ``k i_1 ... i_k`` (the face records of OFF and ASCII PLY)."""
    lens = np.diff(off)
    if len(lens) and (lens == lens[0]).all():  # one format string for all faces
        k = int(lens[0])
        rows = np.hstack([np.full((len(lens), 1), k), idx.reshape(-1, k)])
        return (("%d" + " %d" * k + "\n") * len(lens)) % tuple(rows.ravel().tolist())
    il = idx.tolist()
    return "".join(
        f"{b - a} " + " ".join(map(str, il[a:b])) + "\n"
        for a, b in zip(off[:-1].tolist(), off[1:].tolist(), strict=True)
    )


def _float_strings(A: np.ndarray, precision: int | None) -> list[str]:
    """Numbers as text: shortest exact round-trip form, or ``precision`` significant digits."""
    flat = A.ravel().tolist()
    if precision is None:
        return list(map(repr, flat))
    fmt = f"%.{precision}g"
    return [fmt % x for x in flat]


def _write_text(path: PathLike, text: str) -> None:
    with open(path, "w", encoding="utf-8", newline="\n") as fh:
        fh.write(text)
