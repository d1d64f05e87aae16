"""Mesh files: OBJ, OFF and PLY, read and written with the polygons and per-corner attributes kept.

Meshes follow the libigl convention: ``V`` float64 ``(n, 3)`` and faces as an int64 ``(m, k)``
array when every face has ``k`` corners, otherwise a list of int64 index arrays (polygons).
All indices are 0-based in memory, whatever the file format uses.

Why this is the project's own code. The well-kept readers were tried on the same small files
(``tests/unit/test_mesh_io.py::test_why_not_a_library`` keeps the comparison honest):

* trimesh and libigl (``read_triangle_mesh``) triangulate every polygon, and trimesh splits
  vertices along texture seams, so a quad mesh or a mesh with per-corner UVs changes;
* pyvista/VTK keeps polygons but also splits vertices at UV seams (OBJ), cannot read OFF, and its
  errors are printed warnings, not exceptions that name the line;
* meshio keeps polygons but regroups mixed faces by size (changing their order) and drops the
  per-corner ``vt`` indices, and is not a dependency.

None reports a malformed file with its line number, which students need. So this module keeps
one vectorised parser per format (NumPy reads whole blocks of lines; binary PLY goes through
structured dtypes, with a record walk only for lists of varying length). Python walks tokens
only to name the bad one in an error. A malformed file raises
:class:`~geomlib.validate.MeshError` naming the file, the line (text formats) and the problem::

    read_mesh: bunny.obj, line 12: face index 40 out of range (file has 30 vertices)

A missing file raises :class:`FileNotFoundError`; a folder, FIFO or device a ``MeshError``.
Images are in :mod:`geomlib.image_io`.

This module is over 600 lines because three formats with readers, writers and line-exact error
messages share one set of text helpers; each format has its own section.

Examples
--------
>>> import numpy as np, tempfile, os
>>> from geomlib.mesh_io import read_mesh, write_mesh
>>> V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.0]])
>>> path = os.path.join(tempfile.mkdtemp(), "quad.obj")
>>> write_mesh(path, V, [[0, 1, 2, 3]])
>>> V2, F2 = read_mesh(path, triangulate=True)
>>> F2.tolist()
[[0, 1, 2], [0, 2, 3]]
"""

from __future__ import annotations

import os
import re
import stat
import struct
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from geomlib import topology
from geomlib.validate import MeshError, as_array, as_vertices, check_choice, check_int

__all__ = [
    "ObjData",
    "PlyData",
    "read_mesh",
    "write_mesh",
    "read_obj",
    "write_obj",
    "read_off",
    "write_off",
    "read_ply",
    "write_ply",
    "check_regular_file",
]

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


# --------------------------------------------------------------------------------------------
# Format-independent entry points
# --------------------------------------------------------------------------------------------


def read_mesh(path: PathLike, *, triangulate: bool = False) -> tuple[np.ndarray, Faces]:
    """Read a mesh from an ``.obj``, ``.off`` or ``.ply`` file (chosen by extension).

    Parameters
    ----------
    path : str or path-like
        The file. ``.ply`` may be ASCII or binary, with ``face`` and/or ``tristrips`` elements.
    triangulate : bool
        Fan-triangulate polygons (corner 0 with each consecutive pair), giving ``(m, 3)`` faces.

    Returns
    -------
    V : (n, 3) float64
        Vertex positions.
    F : (m, k) int64 array or list of (k_i,) int64 arrays
        0-based faces: an array when all faces have the same number of corners (or when
        ``triangulate``), otherwise one index array per polygon. A file without faces gives
        an empty ``(0, 3)`` array.

    Raises
    ------
    FileNotFoundError
        The file does not exist.
    MeshError
        Unsupported extension or malformed file (the message names the line).
    """
    where = "read_mesh"
    ext = _ext(path)
    if ext == ".obj":
        d = _read_obj(path, where, triangulate)
        return d.V, d.faces
    if ext == ".off":
        V, F = _read_off(path, where)
    elif ext == ".ply":
        d = _read_ply(path, where)
        V, F = d.V, d.faces
    else:
        raise MeshError(f"{where}: {path}: unsupported extension '{ext}' (supported: {', '.join(MESH_EXTENSIONS)})")
    if triangulate:
        idx, off = topology.to_ragged(F)
        F, _ = _triangulate(idx, off)
    return V, F


def write_mesh(path: PathLike, V, F, **options) -> None:
    """Write a mesh to ``.obj``, ``.off`` or ``.ply`` (chosen by extension).

    Parameters
    ----------
    path : str or path-like
        Output file; its extension picks the format.
    V : (n, 3) array_like of float
        Vertex positions.
    F : (m, k) array_like of int, or list of index sequences
        0-based faces (triangles, quads or mixed polygons).
    **options
        Passed to :func:`write_obj`, :func:`write_off` or :func:`write_ply`
        (e.g. ``UV=``, ``N=``, ``precision=``, ``format="ascii"``).
    """
    ext = _ext(path)
    if ext == ".obj":
        write_obj(path, V, F, **options)
    elif ext == ".off":
        write_off(path, V, F, **options)
    elif ext == ".ply":
        write_ply(path, V, F, **options)
    else:
        raise MeshError(f"write_mesh: {path}: unsupported extension '{ext}' (supported: {', '.join(MESH_EXTENSIONS)})")


# --------------------------------------------------------------------------------------------
# OBJ
# --------------------------------------------------------------------------------------------


@dataclass
class ObjData:
    """Everything :func:`read_obj` keeps from a Wavefront OBJ file.

    Attributes
    ----------
    V : (n, 3) float64
        Vertex positions (a 4th ``w`` coordinate is dropped).
    faces : (m, k) int64 array or list of int64 arrays
        0-based vertex indices per face, as in :func:`read_mesh`.
    UV : (t, 2) float64 or None
        Texture coordinates (``vt`` lines); a missing ``v`` defaults to 0.
    N : (r, 3) float64 or None
        Normals (``vn`` lines).
    face_uv : same structure as ``faces``, or None
        0-based indices into ``UV`` for every face corner; ``-1`` for corners without one.
        None when no face references a texture coordinate.
    face_normal : same structure as ``faces``, or None
        0-based indices into ``N``, ``-1`` for corners without one; None when unused.
    colors : (n, 3) float64 or None
        Per-vertex colours written after ``x y z`` (``v x y z r g b``), when every vertex has them.
    """

    V: np.ndarray
    faces: Faces
    UV: np.ndarray | None = None
    N: np.ndarray | None = None
    face_uv: Faces | None = None
    face_normal: Faces | None = None
    colors: np.ndarray | None = None


def read_obj(path: PathLike, *, triangulate: bool = False) -> ObjData:
    """Read a Wavefront OBJ file, keeping texture coordinates and normals.

    Understands ``v``, ``vt``, ``vn`` and ``f`` lines with ``v``, ``v/vt``, ``v//vn`` and
    ``v/vt/vn`` corners, negative (relative) indices, triangles, quads and general polygons,
    and ``#`` comments. Other statements (``o``, ``g``, ``s``, ``usemtl``, ``mtllib``, ``l``,
    ``p``, ...) are ignored.

    Parameters
    ----------
    path : str or path-like
        The ``.obj`` file.
    triangulate : bool
        Fan-triangulate polygons; ``face_uv`` and ``face_normal`` are triangulated alike.

    Returns
    -------
    ObjData
        ``V``, ``faces``, ``UV``, ``N``, ``face_uv``, ``face_normal``, ``colors``.

    Raises
    ------
    FileNotFoundError
        The file does not exist.
    MeshError
        Malformed file; the message gives the line number and the problem.
    """
    return _read_obj(path, "read_obj", triangulate)


def _read_obj(path: PathLike, where: str, triangulate: bool) -> ObjData:
    src = _Source(where, path)
    data = _read_bytes(path, where)
    text = _TextFile(data, strip_comments=True)
    if np.isin(text.head(1)[:, 0], (9, 32)).any():  # indented lines: drop the indentation
        text = _TextFile(_LEADING_WS.sub(b"", text.data))
    # Keyword of every line from its first three bytes: 'v ', 'vt ', 'vn ', 'f '.
    h = text.head(3)
    end1, end2 = _WS[h[:, 1]] | (h[:, 1] == 0), _WS[h[:, 2]] | (h[:, 2] == 0)
    is_v = h[:, 0] == ord("v")
    rows = {
        b"v": text.rows(np.flatnonzero(is_v & end1), skip=1),
        b"vt": text.rows(np.flatnonzero(is_v & (h[:, 1] == ord("t")) & end2), skip=2),
        b"vn": text.rows(np.flatnonzero(is_v & (h[:, 1] == ord("n")) & end2), skip=2),
        b"f": text.rows(np.flatnonzero((h[:, 0] == ord("f")) & end1), skip=1),
    }
    lines = {k: r.lines for k, r in rows.items()}

    # Vertices: x y z [w] or x y z r g b.
    vdata, vcounts = _parse_float_lines(src, rows[b"v"], what="coordinates after 'v'", minimum=3)
    V = _take_columns(vdata, vcounts, 3)
    _check_finite_rows(src, V, lines[b"v"], "vertex")
    colors = None
    if len(vcounts) and (vcounts >= 6).all():
        starts = np.cumsum(vcounts) - vcounts
        colors = vdata[starts[:, None] + np.array([3, 4, 5])]
    if len(V) == 0:
        raise src.error("no vertices ('v' lines) found; is this an OBJ file?")

    UV = N = None
    if len(rows[b"vt"]):
        tdata, tcounts = _parse_float_lines(src, rows[b"vt"], what="texture coordinate(s) after 'vt'", minimum=1)
        UV = _take_columns(tdata, tcounts, 2)
        _check_finite_rows(src, UV, lines[b"vt"], "texture coordinate")
    if len(rows[b"vn"]):
        ndata, ncounts = _parse_float_lines(src, rows[b"vn"], what="components after 'vn'", minimum=3)
        N = _take_columns(ndata, ncounts, 3)
        _check_finite_rows(src, N, lines[b"vn"], "normal")

    # Faces.
    f_lines = lines[b"f"]
    k, raw_v, raw_t, raw_n, has_t, has_n = _parse_obj_faces(src, rows[b"f"])
    off = np.concatenate([[0], np.cumsum(k)]).astype(np.int64)
    corner_line = np.repeat(f_lines, k)

    def resolve(raw, has, defined_lines, total, name, count_name):
        before = np.repeat(np.searchsorted(defined_lines, f_lines), k)
        res = np.where(raw > 0, raw - 1, before + raw)
        zero = has & (raw == 0)
        bad = has & ((res < 0) | (res >= total) | zero)
        if bad.any():
            j = int(np.flatnonzero(bad)[0])
            r, ln = int(raw[j]), int(corner_line[j])
            if raw[j] == 0:
                raise src.error(f"{name} 0 is invalid (OBJ indices start at 1)", ln)
            if raw[j] < 0:
                raise src.error(
                    f"{name} {r} out of range (only {int(before[j])} {count_name} defined before this line)", ln
                )
            raise src.error(f"{name} {r} out of range (file has {total} {count_name})", ln)
        return np.where(has, res, -1)

    all_corners = np.ones(len(raw_v), dtype=bool)
    idx_v = resolve(raw_v, all_corners, lines[b"v"], len(V), "face index", "vertices")
    idx_t = idx_n = None
    if has_t.any():
        if UV is None:
            j = int(np.flatnonzero(has_t)[0])
            raise src.error("face uses a texture coordinate, but the file has no 'vt' lines", int(corner_line[j]))
        idx_t = resolve(raw_t, has_t, lines[b"vt"], len(UV), "texture coordinate index", "'vt' lines")
    if has_n.any():
        if N is None:
            j = int(np.flatnonzero(has_n)[0])
            raise src.error("face uses a normal, but the file has no 'vn' lines", int(corner_line[j]))
        idx_n = resolve(raw_n, has_n, lines[b"vn"], len(N), "normal index", "'vn' lines")

    if triangulate:
        faces, C = _triangulate(idx_v, off)
        face_uv = idx_t[C] if idx_t is not None else None
        face_normal = idx_n[C] if idx_n is not None else None
    else:
        faces = _ragged_to_faces(idx_v, off)
        face_uv = _ragged_to_faces(idx_t, off) if idx_t is not None else None
        face_normal = _ragged_to_faces(idx_n, off) if idx_n is not None else None
    return ObjData(V=V, faces=faces, UV=UV, N=N, face_uv=face_uv, face_normal=face_normal, colors=colors)


def _parse_obj_faces(src: _Source, rows: _Rows):
    """Parse the ``f`` lines: corner counts and raw (1-based or negative) v/vt/vn indices per corner.

    Vectorised over all corners: each token's format (``v``, ``v/vt``, ``v//vn``, ``v/vt/vn``) comes
    from its slash count, and the tokens of one format are parsed by NumPy in one call, so formats
    may mix even within a face. Python only walks the tokens to name a bad one in the error.
    """
    m, f_lines = len(rows), rows.lines
    if m == 0:
        z = np.zeros(0, np.int64)
        return z, z, z, z, z.astype(bool), z.astype(bool)
    joined = rows.text
    k, b, token_id = _token_layout(joined, m, token_ids=True)
    if (k < 3).any():
        i = int(np.flatnonzero(k < 3)[0])
        raise src.error(f"face has {int(k[i])} vertices, a face needs at least 3", int(f_lines[i]))
    ntok = int(k.sum())
    # Corner format per token from its slash count: 0 'v', 1 'v/vt', 2 'v//vn', 3 'v/vt/vn'.
    slash = b == 47
    s = np.bincount(token_id[slash], minlength=ntok)
    dbl = np.flatnonzero(slash[:-1] & slash[1:])
    d = np.bincount(token_id[dbl], minlength=ntok)
    code = np.full(ntok, -1, dtype=np.int64)
    code[s == 0] = 0
    code[(s == 1) & (d == 0)] = 1
    code[(s == 2) & (d == 1)] = 2
    code[(s == 2) & (d == 0)] = 3
    # Each number is one run of digits: a token like '+' or '1_0' has the wrong count (NumPy would
    # read '+' as 0).
    isdig = (b >= 48) & (b <= 57)
    run = isdig.copy()
    run[1:] &= ~isdig[:-1]
    runs = np.bincount(token_id[run], minlength=ntok)
    code[runs != np.array([1, 2, 2, 3, 0])[code]] = -1
    if (code < 0).any():
        _obj_bad_corner(src, rows, k, int(np.flatnonzero(code < 0)[0]))
    raw_v = np.zeros(ntok, np.int64)
    raw_t = np.zeros(ntok, np.int64)
    raw_n = np.zeros(ntok, np.int64)
    has_t = np.zeros(ntok, bool)
    has_n = np.zeros(ntok, bool)
    present = np.unique(code).tolist()
    for p in present:
        if len(present) == 1:  # one format throughout (the usual case): the text as it is
            text = joined.replace(b"/", b" ") if p else joined
        else:  # the bytes of this format's tokens; slashes and other tokens blanked out
            keep = ~_WS[b] & (code[token_id] == p) & ~slash
            text = np.where(keep, b, np.uint8(32)).tobytes()
        width = (1, 2, 2, 3)[p]
        corners = np.flatnonzero(code == p)
        vals = _fromstring(text, np.int64)
        if vals is None or vals.size != len(corners) * width:
            _obj_bad_corner(src, rows, k, None, corners)
        vals = vals.reshape(-1, width)
        raw_v[corners] = vals[:, 0]
        if p in (1, 3):
            raw_t[corners] = vals[:, 1]
            has_t[corners] = True
        if p in (2, 3):
            raw_n[corners] = vals[:, -1]
            has_n[corners] = True
    return k, raw_v, raw_t, raw_n, has_t, has_n


def _obj_bad_corner(src: _Source, rows: _Rows, k: np.ndarray, corner: int | None, among=None):
    """Raise the error for a face corner that is not ``v``, ``v/vt``, ``v//vn`` or ``v/vt/vn`` integers.

    ``corner`` is the bad corner's index, or None to find the first bad one of the corners ``among``.
    """
    tokens = [t for line in rows.split() for t in line.split()]
    candidates = [corner] if corner is not None else np.asarray(among).tolist()
    for j in candidates:
        parts = tokens[j].split(b"/")
        ok = 1 <= len(parts) <= 3 and parts[0] != b"" and parts[-1] != b""  # only the vt of v//vn may be empty
        if not ok or not all(_is_int(q) for q in parts if q != b""):
            line = int(rows.lines[int(np.searchsorted(np.cumsum(k), j, side="right"))])
            raise src.error(
                f"cannot read face vertex '{tokens[j].decode('latin-1')}' (expected v, v/vt, v//vn or v/vt/vn)", line
            )
    raise src.error("cannot read the faces")  # not reached: NumPy refused a token Python accepts


def _is_int(b: bytes) -> bool:
    digits = b[1:] if b[:1] in (b"+", b"-") else b
    return digits.isdigit()


def write_obj(
    path: PathLike,
    V,
    F,
    UV=None,
    N=None,
    face_uv=None,
    face_normal=None,
    *,
    colors=None,
    precision: int | None = None,
) -> None:
    """Write a Wavefront OBJ file, with optional texture coordinates and normals.

    Parameters
    ----------
    path : str or path-like
        Output ``.obj`` file.
    V : (n, 3) array_like of float
        Vertex positions.
    F : (m, k) array_like of int, or list of index sequences
        0-based faces (any polygon sizes >= 3).
    UV : (t, 2) array_like of float, optional
        Texture coordinates, written as ``vt`` lines.
    N : (r, 3) array_like of float, optional
        Normals, written as ``vn`` lines.
    face_uv, face_normal : same structure as ``F``, optional
        0-based indices into ``UV`` / ``N`` per face corner. When omitted and ``UV`` (``N``)
        has one row per vertex, the vertex indices are used (per-vertex attributes).
    colors : (n, 3) array_like of float, optional
        Per-vertex colours appended to the ``v`` lines (``v x y z r g b``).
    precision : int, optional
        Significant digits for numbers; default: the shortest text that reads back exactly.

    Raises
    ------
    MeshError
        Wrong shapes, out-of-range indices, or attribute indices that do not match ``F``.
    """
    where = "write_obj"
    V = as_vertices(V, where=where)
    n = len(V)
    idx, off = _faces_for_writing(F, n, name="F", where=where)
    if precision is not None:
        precision = check_int(precision, "precision", minimum=1, maximum=17, where=where)
    if colors is not None:
        colors = as_array(colors, "colors", shape=(n, 3), where=where)

    def corner_indices(A, faces, name, fname):
        if A is None:
            if faces is not None:
                raise MeshError(f"{where}: {fname} given without {name}")
            return None
        if faces is None:
            if len(A) != n:
                raise MeshError(
                    f"{where}: {name} has {len(A)} rows but V has {n}; pass {fname} to say which {name} row each "
                    f"face corner uses"
                )
            return idx
        a_idx, a_off = _faces_for_writing(faces, len(A), name=fname, where=where, target=name)
        if len(a_off) != len(off) or not np.array_equal(a_off, off):
            if len(a_off) != len(off):
                raise MeshError(f"{where}: {fname} has {len(a_off) - 1} faces but F has {len(off) - 1}")
            f = int(np.flatnonzero(np.diff(a_off) != np.diff(off))[0])
            raise MeshError(
                f"{where}: face {f} has {int(off[f + 1] - off[f])} corners in F but "
                f"{int(a_off[f + 1] - a_off[f])} in {fname}"
            )
        return a_idx

    if UV is not None:
        UV = as_array(UV, "UV", shape=(None, 2), where=where)
    if N is not None:
        N = as_vertices(N, name="N", where=where)
    t_idx = corner_indices(UV, face_uv, "UV", "face_uv")
    n_idx = corner_indices(N, face_normal, "N", "face_normal")

    out = [f"# written by geomlib.mesh_io: {n} vertices, {len(off) - 1} faces\n"]
    if colors is None:
        out.append(("v %s %s %s\n" * n) % tuple(_float_strings(V, precision)))
    else:
        out.append(("v %s %s %s %s %s %s\n" * n) % tuple(_float_strings(np.hstack([V, colors]), precision)))
    if UV is not None:
        out.append(("vt %s %s\n" * len(UV)) % tuple(_float_strings(UV, precision)))
    if N is not None:
        out.append(("vn %s %s %s\n" * len(N)) % tuple(_float_strings(N, precision)))

    cols = [idx + 1]
    token = "%d"
    if t_idx is not None and n_idx is not None:
        cols += [t_idx + 1, n_idx + 1]
        token = "%d/%d/%d"
    elif t_idx is not None:
        cols.append(t_idx + 1)
        token = "%d/%d"
    elif n_idx is not None:
        cols.append(n_idx + 1)
        token = "%d//%d"
    corners = np.stack(cols, axis=1)  # (corners, 1..3), 1-based
    lens = np.diff(off)
    if len(lens) and (lens == lens[0]).all():
        line = "f " + " ".join([token] * int(lens[0])) + "\n"
        out.append((line * len(lens)) % tuple(corners.ravel().tolist()))
    else:
        toks = (" ".join([token] * len(corners)) % tuple(corners.ravel().tolist())).split(" ") if len(corners) else []
        out.extend("f " + " ".join(toks[a:b]) + "\n" for a, b in zip(off[:-1].tolist(), off[1:].tolist(), strict=True))
    _write_text(path, "".join(out))


# --------------------------------------------------------------------------------------------
# OFF
# --------------------------------------------------------------------------------------------


def read_off(path: PathLike) -> tuple[np.ndarray, Faces]:
    """Read an OFF file (also ``COFF``, ``NOFF``, ``CNOFF``, ``STOFF`` variants).

    Extra per-vertex values (normals, colours, texture coordinates) and face colours after the
    face indices are ignored. ``#`` comments and blank lines are allowed anywhere.

    Parameters
    ----------
    path : str or path-like
        The ``.off`` file.

    Returns
    -------
    V : (n, 3) float64
    F : (m, k) int64 array or list of int64 arrays
        0-based faces, as in :func:`read_mesh`.

    Raises
    ------
    FileNotFoundError
        The file does not exist.
    MeshError
        Malformed file; the message gives the line number and the problem.
    """
    return _read_off(path, "read_off")


def _read_off(path: PathLike, where: str) -> tuple[np.ndarray, Faces]:
    src = _Source(where, path)
    data = _read_bytes(path, where)
    text = _TextFile(data, strip_comments=True)
    content = text.nonblank()  # line indices
    line_nums = text.line_number(content)
    if len(content) == 0:
        raise src.error("file is empty")
    head = text.line(int(content[0])).split()
    magic = head[0].decode("latin-1")
    prefix = magic[:-3] if magic.endswith("OFF") else None
    if prefix is None or set(prefix) - set("STCN") or len(prefix) > 4:
        if prefix is not None and ("4" in prefix or "n" in prefix):
            raise src.error(f"'{magic}' (higher-dimensional OFF) is not supported", int(line_nums[0]))
        raise src.error(f"expected the header 'OFF', got '{magic}'", int(line_nums[0]))
    if len(head) > 1 and head[1].upper() == b"BINARY":
        raise src.error("binary OFF is not supported", int(line_nums[0]))
    pos = 1
    counts_tokens, counts_line = head[1:], int(line_nums[0])
    if not counts_tokens:
        if len(content) < 2:
            raise src.error("file ends before the counts line 'n_vertices n_faces n_edges'", int(line_nums[0]))
        counts_tokens, counts_line = text.line(int(content[1])).split(), int(line_nums[1])
        pos = 2
    try:
        if len(counts_tokens) < 2:
            raise ValueError
        nv, nf = int(counts_tokens[0]), int(counts_tokens[1])
        if nv < 0 or nf < 0:
            raise ValueError
    except ValueError:
        got = b" ".join(counts_tokens).decode("latin-1")
        raise src.error(f"expected counts 'n_vertices n_faces n_edges', got '{got}'", counts_line) from None
    if len(content) < pos + nv + nf:
        have_v = min(nv, len(content) - pos)
        have_f = max(0, len(content) - pos - nv)
        what = f"{have_v} of {nv} vertices" if have_v < nv else f"{have_f} of {nf} faces"
        raise src.error(
            f"file ends after {what} (the header announces {nv} vertices and {nf} faces)", int(line_nums[-1])
        )

    vrows = text.rows(content[pos : pos + nv])
    vdata, vcounts = _parse_float_lines(src, vrows, what="coordinates on a vertex line", minimum=3)
    V = _take_columns(vdata, vcounts, 3)
    _check_finite_rows(src, V, vrows.lines, "vertex")

    frows = text.rows(content[pos + nv : pos + nv + nf])
    fl = frows.lines
    fdata, fcounts = _parse_float_lines(
        src, frows, what="values on a face line (count, indices...)", minimum=1, try_int=True
    )
    if nf == 0:
        return V, np.zeros((0, 3), np.int64)
    starts = np.cumsum(fcounts) - fcounts
    k_f = fdata[starts]
    bad = (k_f != np.round(k_f)) | (k_f < 3)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise src.error(f"face has {k_f[i]:g} vertices, a face needs at least 3 (an integer)", int(fl[i]))
    k = k_f.astype(np.int64)
    short = fcounts < k + 1
    if short.any():
        i = int(np.flatnonzero(short)[0])
        raise src.error(f"face says {k[i]} vertices but lists {int(fcounts[i]) - 1} indices", int(fl[i]))
    off = np.concatenate([[0], np.cumsum(k)]).astype(np.int64)
    pos_in = np.arange(off[-1]) - np.repeat(off[:-1], k)
    vals = fdata[np.repeat(starts + 1, k) + pos_in]
    corner_line = np.repeat(fl, k)
    bad = (vals != np.round(vals)) | (vals < 0) | (vals >= nv)
    if bad.any():
        j = int(np.flatnonzero(bad)[0])
        x = vals[j]
        if x != np.round(x):
            raise src.error(f"face index {x:g} is not an integer", int(corner_line[j]))
        raise src.error(
            f"face index {int(x)} out of range (file has {nv} vertices, valid indices 0..{nv - 1})", int(corner_line[j])
        )
    return V, _ragged_to_faces(vals.astype(np.int64), off)


def write_off(path: PathLike, V, F, *, precision: int | None = None) -> None:
    """Write an OFF file.

    Parameters
    ----------
    path : str or path-like
        Output ``.off`` file.
    V : (n, 3) array_like of float
        Vertex positions.
    F : (m, k) array_like of int, or list of index sequences
        0-based faces (any polygon sizes >= 3).
    precision : int, optional
        Significant digits; default: the shortest text that reads back exactly.
    """
    where = "write_off"
    V = as_vertices(V, where=where)
    idx, off = _faces_for_writing(F, len(V), name="F", where=where)
    if precision is not None:
        precision = check_int(precision, "precision", minimum=1, maximum=17, where=where)
    lens = np.diff(off)
    out = [f"OFF\n{len(V)} {len(lens)} 0\n", ("%s %s %s\n" * len(V)) % tuple(_float_strings(V, precision))]
    if len(lens) and (lens == lens[0]).all():
        k = int(lens[0])
        rows = np.hstack([np.full((len(lens), 1), k), idx.reshape(-1, k)])
        out.append((("%d" + " %d" * k + "\n") * len(lens)) % tuple(rows.ravel().tolist()))
    else:
        il = idx.tolist()
        out.extend(
            f"{b - a} " + " ".join(map(str, il[a:b])) + "\n"
            for a, b in zip(off[:-1].tolist(), off[1:].tolist(), strict=True)
        )
    _write_text(path, "".join(out))


# --------------------------------------------------------------------------------------------
# PLY
# --------------------------------------------------------------------------------------------

_PLY_TYPES = {
    "char": "i1",
    "int8": "i1",
    "uchar": "u1",
    "uint8": "u1",
    "short": "i2",
    "int16": "i2",
    "ushort": "u2",
    "uint16": "u2",
    "int": "i4",
    "int32": "i4",
    "uint": "u4",
    "uint32": "u4",
    "float": "f4",
    "float32": "f4",
    "double": "f8",
    "float64": "f8",
}
_PLY_FORMATS = ("ascii", "binary_little_endian", "binary_big_endian")
_UV_NAMES = (("u", "v"), ("s", "t"), ("texture_u", "texture_v"), ("texture_s", "texture_t"))


@dataclass
class _PlyProp:
    name: str
    code: str  # item type, numpy code without byte order
    count_code: str | None = None  # list length type; None for scalars


@dataclass
class _PlyElement:
    name: str
    count: int
    line: int
    props: list[_PlyProp] = field(default_factory=list)


@dataclass
class PlyData:
    """What :func:`read_ply` returns.

    Attributes
    ----------
    V : (n, 3) float64
        Vertex positions.
    faces : (m, k) int64 array or list of int64 arrays
        0-based faces from the ``face`` element followed by the triangles decoded from
        ``tristrips``, as in :func:`read_mesh`.
    N : (n, 3) float64 or None
        Vertex normals (``nx, ny, nz``).
    UV : (n, 2) float64 or None
        Vertex texture coordinates (``u, v``, ``s, t``, ``texture_u, texture_v`` or
        ``texture_s, texture_t``).
    colors : (n, 3) or (n, 4) array or None
        Vertex colours (``red, green, blue[, alpha]``) in the file's type (usually uint8).
    vertex_properties : dict of str to (n,) array
        Every scalar vertex property, by name, in the file's type.
    """

    V: np.ndarray
    faces: Faces
    N: np.ndarray | None = None
    UV: np.ndarray | None = None
    colors: np.ndarray | None = None
    vertex_properties: dict[str, np.ndarray] = field(default_factory=dict)


def read_ply(path: PathLike) -> PlyData:
    """Read a PLY file: ASCII, binary little endian or binary big endian.

    The ``vertex`` element needs ``x, y, z`` (any numeric type); normals, texture coordinates and
    colours are kept when present. Faces come from the ``face`` element (list property
    ``vertex_indices`` or ``vertex_index``, any count/index types) and from the ``tristrips``
    element, whose strips are separated by ``-1``: triangle ``j`` of a strip ``s`` is
    ``(s[j], s[j+1], s[j+2])`` for even ``j`` and ``(s[j+1], s[j], s[j+2])`` for odd ``j``, and
    degenerate triangles (a repeated vertex) are dropped. Other elements are skipped.

    Parameters
    ----------
    path : str or path-like
        The ``.ply`` file.

    Returns
    -------
    PlyData
        ``V``, ``faces``, ``N``, ``UV``, ``colors``, ``vertex_properties``.

    Raises
    ------
    FileNotFoundError
        The file does not exist.
    MeshError
        Malformed header, truncated binary data, bad values (ASCII errors give the line number).
    """
    return _read_ply(path, "read_ply")


def _parse_ply_header(src: _Source, data: bytes) -> tuple[str, list[_PlyElement], int, int]:
    """Returns ``(format, elements, body byte offset, number of header lines)``."""
    if not data.startswith(b"ply"):
        raise src.error("not a PLY file (it does not start with 'ply')", 1)
    end = data.find(b"end_header")
    if end < 0:
        raise src.error("the header has no 'end_header' line")
    nl = data.find(b"\n", end)
    body = len(data) if nl < 0 else nl + 1
    head_lines = data[:end].decode("latin-1").split("\n")
    fmt = None
    elements: list[_PlyElement] = []
    for i, raw in enumerate(head_lines[1:], start=2):
        tok = raw.split()
        if not tok or tok[0] in ("comment", "obj_info"):
            continue
        if tok[0] == "format":
            if len(tok) < 2 or tok[1] not in _PLY_FORMATS:
                raise src.error(f"unknown format '{raw.strip()}' (expected one of {', '.join(_PLY_FORMATS)})", i)
            fmt = tok[1]
        elif tok[0] == "element":
            try:
                if len(tok) != 3:
                    raise ValueError
                count = int(tok[2])
                if count < 0:
                    raise ValueError
            except ValueError:
                raise src.error(f"expected 'element <name> <count>', got '{raw.strip()}'", i) from None
            elements.append(_PlyElement(tok[1], count, i))
        elif tok[0] == "property":
            if not elements:
                raise src.error("'property' before any 'element'", i)
            if len(tok) == 5 and tok[1] == "list" and tok[2] in _PLY_TYPES and tok[3] in _PLY_TYPES:
                if _PLY_TYPES[tok[2]][0] == "f":
                    raise src.error(f"list count type must be an integer type, got '{tok[2]}'", i)
                elements[-1].props.append(_PlyProp(tok[4], _PLY_TYPES[tok[3]], _PLY_TYPES[tok[2]]))
            elif len(tok) == 3 and tok[1] in _PLY_TYPES:
                elements[-1].props.append(_PlyProp(tok[2], _PLY_TYPES[tok[1]]))
            else:
                raise src.error(
                    f"cannot read property '{raw.strip()}' (types: {', '.join(sorted(set(_PLY_TYPES)))})", i
                )
        else:
            raise src.error(f"unexpected header line '{raw.strip()}'", i)
    if fmt is None:
        raise src.error("the header has no 'format' line")
    return fmt, elements, body, len(head_lines)


def _read_ply(path: PathLike, where: str) -> PlyData:
    src = _Source(where, path)
    data = _read_bytes(path, where)
    fmt, elements, body, n_head = _parse_ply_header(src, data)
    values: dict[str, dict] = {}
    lines: dict[str, np.ndarray] = {}
    if fmt == "ascii":
        text = _TextFile(data[body:], first_line=n_head + 1)
        content = text.nonblank()
        pos = 0
        for el in elements:
            if pos + el.count > len(content):
                last = int(text.line_number(content[-1])) if len(content) else n_head
                raise src.error(
                    f"file ends after {len(content) - pos} of {el.count} '{el.name}' records (header line {el.line})",
                    last,
                )
            rows = text.rows(content[pos : pos + el.count])
            values[el.name] = _ply_ascii_element(src, el, rows)
            lines[el.name] = rows.lines
            pos += el.count
    else:
        order = "<" if fmt == "binary_little_endian" else ">"
        pos = body
        for el in elements:
            values[el.name], pos = _ply_binary_element(src, el, data, pos, order)
    return _ply_assemble(src, values, lines)


def _ply_ascii_element(src: _Source, el: _PlyElement, rows: _Rows) -> dict:
    """Parse one element's lines; scalars -> (count,) arrays, lists -> (flat, offsets).

    Vectorised over records: every record gets a read position, and one pass over the properties
    advances it (by 1 for a scalar, by 1 + its length for a list), so any number of lists works.
    """
    out: dict = {}
    ln = rows.lines
    if el.count == 0:
        for p in el.props:
            out[p.name] = np.zeros(0, p.code) if p.count_code is None else (np.zeros(0, p.code), np.zeros(1, np.int64))
        return out
    names = " ".join(p.name for p in el.props)
    all_int = all(np.dtype(p.code).kind in "iu" for p in el.props)
    data, counts = _parse_float_lines(src, rows, what=f"values for '{el.name}' ({names})", minimum=0, try_int=all_int)
    n_lists = sum(p.count_code is not None for p in el.props)
    if n_lists == 0 and (counts != len(el.props)).any():
        i = int(np.flatnonzero(counts != len(el.props))[0])
        raise src.error(f"expected {len(el.props)} values for '{el.name}' ({names}), got {int(counts[i])}", int(ln[i]))
    pos = np.cumsum(counts) - counts  # read position of every record in `data`
    end = pos + counts
    for j, p in enumerate(el.props):
        later = len(el.props) - j - 1  # each later property takes at least one value
        if (pos >= end).any():
            i = int(np.flatnonzero(pos >= end)[0])
            raise src.error(
                f"expected at least {int(pos[i] - end[i] + counts[i]) + 1 + later} values for '{el.name}' ({names})",
                int(ln[i]),
            )
        first = data[pos]
        if p.count_code is None:
            out[p.name] = _ply_cast(src, first, p, el, ln)
            pos = pos + 1
            continue
        bad = (first != np.round(first)) | (first < 0)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise src.error(f"list length {first[i]:g} of '{p.name}' is not a non-negative integer", int(ln[i]))
        c = first.astype(np.int64)
        avail = end - pos - 1 - later
        last_list = not any(q.count_code is not None for q in el.props[j + 1 :])
        bad = (c != avail) if last_list else (c > avail)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise src.error(
                f"'{p.name}' says {c[i]} entries, but the line has {int(avail[i])} "
                f"(expected {int(counts[i] - avail[i] + c[i])} values: {names})",
                int(ln[i]),
            )
        off = np.concatenate([[0], np.cumsum(c)]).astype(np.int64)
        items = data[np.repeat(pos + 1, c) + (np.arange(off[-1]) - np.repeat(off[:-1], c))]
        out[p.name] = (_ply_cast(src, items, p, el, np.repeat(ln, c)), off)
        pos = pos + 1 + c
    return out


def _ply_cast(src: _Source, a: np.ndarray, p: _PlyProp, el: _PlyElement, ln: np.ndarray | None) -> np.ndarray:
    """ASCII values (parsed as float64 or int64) to the declared type, rejecting non-integers for int types."""
    dt = np.dtype(p.code)
    if dt.kind in "iu":
        info = np.iinfo(dt)
        bad = (a != np.round(a)) | (a < info.min) | (a > info.max)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            line = int(ln[i]) if ln is not None else None
            raise src.error(f"'{el.name}' property '{p.name}' is {dt.name}, got {a[i]:g}", line)
    return a.astype(dt)


def _ply_binary_element(src: _Source, el: _PlyElement, data: bytes, pos: int, order: str) -> tuple[dict, int]:
    """Read one element from binary data at byte ``pos``; returns its values and the next position."""
    out: dict = {}
    n = el.count
    remaining = len(data) - pos

    def truncated(record: int, detail: str = "") -> MeshError:
        return src.error(
            f"file is truncated: the binary data ends inside '{el.name}' record {record + 1} of {n} "
            f"(element declared on header line {el.line}){detail}"
        )

    if all(p.count_code is None for p in el.props):
        dt = np.dtype([(p.name, order + p.code) for p in el.props])
        need = dt.itemsize * n
        if need > remaining:
            raise truncated(remaining // max(dt.itemsize, 1))
        arr = np.frombuffer(data, dtype=dt, count=n, offset=pos)
        return {p.name: arr[p.name] for p in el.props}, pos + need
    if n == 0:
        for p in el.props:
            out[p.name] = np.zeros(0, p.code) if p.count_code is None else (np.zeros(0, p.code), np.zeros(1, np.int64))
        return out, pos

    # Every list as long as in the first record (e.g. all triangles): the element is one
    # fixed-size structured array. Otherwise walk the records for their list lengths.
    fields, q = [], pos
    for j, p in enumerate(el.props):
        if p.count_code is None:
            fields.append((f"s{j}", order + p.code))
            q += np.dtype(p.code).itemsize
        else:
            csz = np.dtype(p.count_code).itemsize
            if q + csz > len(data):
                raise truncated(0)
            c = int(np.frombuffer(data, order + p.count_code, 1, q)[0])
            _check_list_length(src, el, p, 0, c, len(data) - q - csz, truncated)
            fields += [(f"c{j}", order + p.count_code), (f"s{j}", order + p.code, (c,))]
            q += csz + c * np.dtype(p.code).itemsize
    dt = np.dtype(fields)
    if dt.itemsize * n <= remaining:
        arr = np.frombuffer(data, dtype=dt, count=n, offset=pos)
        same = all((arr[f"c{j}"] == arr[f"c{j}"][0]).all() for j, p in enumerate(el.props) if p.count_code is not None)
        if same:
            for j, p in enumerate(el.props):
                if p.count_code is None:
                    out[p.name] = arr[f"s{j}"]
                else:
                    items = arr[f"s{j}"]
                    c = items.shape[1]
                    out[p.name] = (items.reshape(-1), np.arange(n + 1, dtype=np.int64) * c)
            return out, pos + dt.itemsize * n
    return _ply_binary_walk(src, el, data, pos, order, truncated)


def _check_list_length(src: _Source, el: _PlyElement, p: _PlyProp, record: int, c: int, left: int, truncated) -> None:
    """A binary list length must be >= 0 and fit in the bytes left (a corrupt count, e.g. 2**31 - 1, would
    otherwise ask NumPy for gigabytes)."""
    if c < 0:
        raise src.error(f"record {record} of '{el.name}' has a negative list length {c} for '{p.name}'")
    size = np.dtype(p.code).itemsize
    if c * size > left:
        raise truncated(
            record,
            f"; its list '{p.name}' says {c} entries ({c * size} bytes) but {max(left, 0)} bytes are left, "
            f"so the file is cut short or that list length is corrupt",
        )


def _ply_binary_walk(src, el, data, pos, order, truncated):
    """Variable-length lists: walk the records for the list lengths, then gather items with NumPy."""
    n = el.count
    sizes = [np.dtype(p.code).itemsize for p in el.props]
    count_structs = [
        None if p.count_code is None else struct.Struct(order + np.dtype(p.count_code).char) for p in el.props
    ]
    starts: list[list[int]] = [[] for _ in el.props]
    lens: list[list[int]] = [[] for _ in el.props]
    q, end = pos, len(data)
    for r in range(n):
        for j, p in enumerate(el.props):
            cs = count_structs[j]
            if cs is None:
                starts[j].append(q)
                q += sizes[j]
            else:
                if q + cs.size > end:
                    raise truncated(r)
                c = cs.unpack_from(data, q)[0]
                _check_list_length(src, el, p, r, c, end - q - cs.size, truncated)
                q += cs.size
                starts[j].append(q)
                lens[j].append(c)
                q += c * sizes[j]
        if q > end:
            raise truncated(r)
    buf = np.frombuffer(data, dtype=np.uint8)
    out: dict = {}
    for j, p in enumerate(el.props):
        dt = np.dtype(order + p.code)
        st = np.array(starts[j], dtype=np.int64)
        if p.count_code is None:
            c = np.ones(n, dtype=np.int64)
        else:
            c = np.array(lens[j], dtype=np.int64)
        off = np.concatenate([[0], np.cumsum(c)]).astype(np.int64)
        if n <= 64:  # few long records (e.g. one tristrips record): read each list in one go
            parts = [np.frombuffer(data, dt, int(k), int(s0)) for s0, k in zip(st, c, strict=True)]
            items = np.concatenate(parts) if parts else np.zeros(0, dt)
        else:
            item_start = np.repeat(st, c) + (np.arange(off[-1]) - np.repeat(off[:-1], c)) * sizes[j]
            byte_idx = item_start[:, None] + np.arange(sizes[j])
            items = buf[byte_idx].reshape(-1).view(dt) if off[-1] else np.zeros(0, dt)
        out[p.name] = items if p.count_code is None else (items, off)
    return out, q


def _decode_tristrips(strips: np.ndarray) -> np.ndarray:
    """Triangles ``(t, 3)`` from ``-1``-separated strips, alternating winding, degenerates dropped."""
    s = np.asarray(strips, dtype=np.int64)
    if s.size < 3:
        return np.zeros((0, 3), np.int64)
    sep = s < 0
    a, b, c = s[:-2], s[1:-1], s[2:]
    keep = ~(sep[:-2] | sep[1:-1] | sep[2:]) & (a != b) & (b != c) & (a != c)
    i = np.flatnonzero(keep)
    # Triangle parity counts from the first index of its strip (just after the previous -1).
    strip_start = np.concatenate([[0], np.flatnonzero(sep) + 1])[np.cumsum(sep)[i]]
    odd = ((i - strip_start) & 1).astype(bool)
    a, b, c = a[i], b[i], c[i]
    return np.stack([np.where(odd, b, a), np.where(odd, a, b), c], axis=1)


def _ply_assemble(src: _Source, values: dict, lines: dict) -> PlyData:
    if "vertex" not in values:
        raise src.error("the file has no 'vertex' element")
    vert = values["vertex"]
    scalars = {k: v for k, v in vert.items() if not isinstance(v, tuple)}
    missing = [c for c in "xyz" if c not in scalars]
    if missing:
        raise src.error(
            f"the 'vertex' element has no {', '.join(missing)} propert{'y' if len(missing) == 1 else 'ies'}"
        )
    V = np.stack([scalars[c] for c in "xyz"], axis=1).astype(np.float64)
    vl = lines.get("vertex")
    _check_finite_rows(src, V, vl, "vertex")
    nv = len(V)
    N = np.stack([scalars[c] for c in ("nx", "ny", "nz")], axis=1).astype(np.float64) if "nx" in scalars else None
    if N is not None and not all(c in scalars for c in ("ny", "nz")):
        N = None
    UV = None
    for a, b in _UV_NAMES:
        if a in scalars and b in scalars:
            UV = np.stack([scalars[a], scalars[b]], axis=1).astype(np.float64)
            break
    colors = None
    if all(c in scalars for c in ("red", "green", "blue")):
        names = ["red", "green", "blue"] + (["alpha"] if "alpha" in scalars else [])
        colors = np.stack([scalars[c] for c in names], axis=1)

    parts_idx, parts_off = [], []
    if "face" in values:
        face = values["face"]
        key = next((k for k in ("vertex_indices", "vertex_index") if isinstance(face.get(k), tuple)), None)
        if key is None:
            raise src.error("the 'face' element has no list property 'vertex_indices' (or 'vertex_index')")
        idx, off = face[key]
        idx = idx.astype(np.int64)
        lens = np.diff(off)
        if (lens < 3).any():
            f = int(np.flatnonzero(lens < 3)[0])
            line = int(lines["face"][f]) if "face" in lines else None
            raise src.error(f"face {f} has {int(lens[f])} vertices, a face needs at least 3", line)
        _ply_check_indices(src, idx, off, nv, "face", lines.get("face"))
        parts_idx.append(idx)
        parts_off.append(off)
    if "tristrips" in values:
        ts = values["tristrips"]
        key = next((k for k in ("vertex_indices", "vertex_index") if isinstance(ts.get(k), tuple)), None)
        if key is None:
            raise src.error("the 'tristrips' element has no list property 'vertex_indices'")
        sidx, soff = ts[key]
        sidx = sidx.astype(np.int64)
        bad = (sidx < -1) | (sidx >= nv)
        if bad.any():
            j = int(np.flatnonzero(bad)[0])
            r = int(np.searchsorted(soff, j, side="right") - 1)
            line = int(lines["tristrips"][r]) if "tristrips" in lines else None
            raise src.error(f"tristrips index {int(sidx[j])} out of range (file has {nv} vertices)", line)
        # Each record is its own strip: separate records with -1 before decoding.
        rec = np.insert(sidx, soff[1:-1], -1) if len(soff) > 2 else sidx
        T = _decode_tristrips(rec)
        parts_idx.append(T.ravel())
        parts_off.append(np.arange(0, T.size + 1, 3, dtype=np.int64))
    if parts_idx:
        idx = np.concatenate(parts_idx)
        off = parts_off[0]
        for o in parts_off[1:]:
            off = np.concatenate([off, o[1:] + off[-1]])
        faces = _ragged_to_faces(idx, off)
    else:
        faces = np.zeros((0, 3), np.int64)
    return PlyData(V=V, faces=faces, N=N, UV=UV, colors=colors, vertex_properties=scalars)


def _ply_check_indices(src, idx, off, nv, name, ln) -> None:
    bad = (idx < 0) | (idx >= nv)
    if bad.any():
        j = int(np.flatnonzero(bad)[0])
        f = int(np.searchsorted(off, j, side="right") - 1)
        msg = f"{name} index {int(idx[j])} out of range (file has {nv} vertices, valid indices 0..{nv - 1})"
        if ln is not None:
            raise src.error(msg, int(ln[f]))
        raise src.error(f"{name} {f}: {msg}")


def write_ply(
    path: PathLike,
    V,
    F=None,
    *,
    N=None,
    UV=None,
    colors=None,
    format: str = "binary_little_endian",
    vertex_type: str = "double",
    precision: int | None = None,
) -> None:
    """Write a PLY file (binary little endian by default, or ASCII / binary big endian).

    Parameters
    ----------
    path : str or path-like
        Output ``.ply`` file.
    V : (n, 3) array_like of float
        Vertex positions.
    F : (m, k) array_like of int, or list of index sequences, optional
        0-based faces, written as ``element face`` with ``property list uchar int vertex_indices``
        (``int`` list lengths if a face has more than 255 corners). None writes a point cloud.
    N : (n, 3) array_like of float, optional
        Vertex normals (``nx, ny, nz``).
    UV : (n, 2) array_like of float, optional
        Vertex texture coordinates (``u, v``).
    colors : (n, 3) or (n, 4) array_like of uint8, optional
        Vertex colours (``red, green, blue[, alpha]``), 0..255.
    format : {"binary_little_endian", "binary_big_endian", "ascii"}
        PLY flavour.
    vertex_type : {"double", "float"}
        Type of the vertex properties (``float`` halves the size but rounds to float32).
    precision : int, optional
        ASCII only: significant digits; default the shortest exact text.
    """
    where = "write_ply"
    V = as_vertices(V, where=where)
    n = len(V)
    check_choice(format, "format", _PLY_FORMATS, where=where)
    check_choice(vertex_type, "vertex_type", ("double", "float"), where=where)
    if precision is not None:
        precision = check_int(precision, "precision", minimum=1, maximum=17, where=where)
    if F is None:
        idx, off = np.zeros(0, np.int64), np.zeros(1, np.int64)
    else:
        idx, off = _faces_for_writing(F, n, name="F", where=where)
    if n > 2**31 - 1:
        raise MeshError(f"{where}: {n} vertices: indices above 2^31 - 1 do not fit PLY 'int'")
    cols: list[tuple[str, np.ndarray]] = [(c, V[:, j]) for j, c in enumerate("xyz")]
    if N is not None:
        N = as_vertices(N, name="N", where=where)
        if len(N) != n:
            raise MeshError(f"{where}: N has {len(N)} rows but V has {n}; PLY stores one normal per vertex")
        cols += [(c, N[:, j]) for j, c in enumerate(("nx", "ny", "nz"))]
    if UV is not None:
        UV = as_array(UV, "UV", shape=(n, 2), where=where)
        cols += [("u", UV[:, 0]), ("v", UV[:, 1])]
    ncol = 0
    if colors is not None:
        C = np.asarray(colors)
        if C.ndim != 2 or C.shape[0] != n or C.shape[1] not in (3, 4):
            raise MeshError(f"{where}: colors has shape {C.shape}, expected ({n}, 3) or ({n}, 4)")
        C = as_array(C, "colors", dtype=np.int64, where=where)
        if C.size and (C.min() < 0 or C.max() > 255):
            raise MeshError(f"{where}: colors must be integers in 0..255 (got {C.min()}..{C.max()})")
        ncol = C.shape[1]
    fcode = "f8" if vertex_type == "double" else "f4"
    lens = np.diff(off)
    m = len(lens)
    count_t = "uchar" if m == 0 or lens.max() <= 255 else "int"
    head = ["ply", f"format {format} 1.0", "comment written by geomlib.mesh_io", f"element vertex {n}"]
    head += [f"property {vertex_type} {c}" for c, _ in cols]
    head += [f"property uchar {c}" for c in ("red", "green", "blue", "alpha")[:ncol]]
    if F is not None:
        head += [f"element face {m}", f"property list {count_t} int vertex_indices"]
    head.append("end_header\n")
    header = "\n".join(head).encode("ascii")

    if format == "ascii":
        out = [header.decode("ascii")]
        table = np.stack([a for _, a in cols], axis=1)
        if vertex_type == "float" and precision is None:
            strs = list(map(str, table.astype(np.float32).ravel()))  # shortest float32 text
        else:
            strs = _float_strings(table, precision)
        if ncol:
            width = len(cols)
            strs = np.array(strs, dtype=object).reshape(n, width)
            strs = np.hstack([strs, C.astype(str).astype(object)]).ravel().tolist()
        per = len(cols) + ncol
        out.append(((" ".join(["%s"] * per) + "\n") * n) % tuple(strs))
        if F is not None:
            if m and (lens == lens[0]).all():
                k = int(lens[0])
                rows = np.hstack([np.full((m, 1), k), idx.reshape(-1, k)])
                out.append((("%d" + " %d" * k + "\n") * m) % tuple(rows.ravel().tolist()))
            else:
                il = idx.tolist()
                out.extend(
                    f"{b - a} " + " ".join(map(str, il[a:b])) + "\n"
                    for a, b in zip(off[:-1].tolist(), off[1:].tolist(), strict=True)
                )
        _write_text(path, "".join(out))
        return

    order = "<" if format == "binary_little_endian" else ">"
    vdt = np.dtype(
        [(c, order + fcode) for c, _ in cols] + [(c, "u1") for c in ("red", "green", "blue", "alpha")[:ncol]]
    )
    vrec = np.empty(n, dtype=vdt)
    for c, a in cols:
        vrec[c] = a
    for j, c in enumerate(("red", "green", "blue", "alpha")[:ncol]):
        vrec[c] = C[:, j]
    chunks = [header, vrec.tobytes()]
    if F is not None and m:
        ct = np.dtype(order + ("u1" if count_t == "uchar" else "i4"))
        it = np.dtype(order + "i4")
        if (lens == lens[0]).all():
            k = int(lens[0])
            frec = np.empty(m, dtype=np.dtype([("c", ct), ("i", it, (k,))]))
            frec["c"] = k
            frec["i"] = idx.reshape(m, k)
            chunks.append(frec.tobytes())
        else:
            rec_size = ct.itemsize + lens * 4
            rec_start = np.concatenate([[0], np.cumsum(rec_size)[:-1]])
            buf = np.empty(int(rec_size.sum()), np.uint8)
            cbytes = lens.astype(ct).view(np.uint8).reshape(m, ct.itemsize)
            buf[rec_start[:, None] + np.arange(ct.itemsize)] = cbytes
            item_pos = np.repeat(rec_start + ct.itemsize, lens) + (np.arange(len(idx)) - np.repeat(off[:-1], lens)) * 4
            buf[item_pos[:, None] + np.arange(4)] = idx.astype(it).view(np.uint8).reshape(-1, 4)
            chunks.append(buf.tobytes())
    with open(path, "wb") as fh:
        fh.write(b"".join(chunks))
