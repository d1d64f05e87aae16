"""PLY, ASCII and binary: reader (faces and tristrips, vertex attributes) and writer.

One format, one module (about 630 lines): the header grammar, the ASCII and binary record walks and
the writer share the element and property descriptions; no well-kept library reads PLY polygons
with line-numbered errors (see :mod:`geomlib.mesh_io`).
"""

from __future__ import annotations

import struct
from dataclasses import dataclass, field

import numpy as np

from geomlib.mesh_io._text import (
    Faces,
    PathLike,
    _check_finite_rows,
    _counted_face_lines,
    _float_strings,
    _parse_float_lines,
    _ragged_to_faces,
    _read_bytes,
    _Rows,
    _Source,
    _TextFile,
    _write_text,
    _writer_inputs,
)
from geomlib.validate import MeshError, as_array, as_vertices, check_choice

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
                if c < 0 or q + cs.size + c * sizes[j] > end:
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
        idx, off = _ply_index_lists(src, values, "face")
        lens = np.diff(off)
        if (lens < 3).any():
            f = int(np.flatnonzero(lens < 3)[0])
            line = int(lines["face"][f]) if "face" in lines else None
            raise src.error(f"face {f} has {int(lens[f])} vertices, a face needs at least 3", line)
        _ply_check_indices(src, idx, off, nv, "face", lines.get("face"))
        parts_idx.append(idx)
        parts_off.append(off)
    if "tristrips" in values:
        sidx, soff = _ply_index_lists(src, values, "tristrips")
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


def _ply_index_lists(src, values, element: str) -> tuple[np.ndarray, np.ndarray]:
    """The ``(idx, off)`` vertex-index lists of ``element`` (``face`` or ``tristrips``), idx as int64."""
    props = values[element]
    key = next((k for k in ("vertex_indices", "vertex_index") if isinstance(props.get(k), tuple)), None)
    if key is None:
        raise src.error(f"the '{element}' element has no list property 'vertex_indices' (or 'vertex_index')")
    idx, off = props[key]
    return idx.astype(np.int64), off


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
    path, V
        As in :func:`~geomlib.mesh_io.write_mesh`.
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
        ASCII only; as in :func:`~geomlib.mesh_io.write_mesh`.
    """
    where = "write_ply"
    V, idx, off, precision = _writer_inputs(V, F, precision, where, faces_optional=True)
    n = len(V)
    check_choice(format, "format", _PLY_FORMATS, where=where)
    check_choice(vertex_type, "vertex_type", ("double", "float"), where=where)
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
            out.append(_counted_face_lines(idx, off))
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
