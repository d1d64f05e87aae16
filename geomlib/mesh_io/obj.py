"""Wavefront OBJ: reader (positions, texture coordinates, normals, per-corner indices) and writer."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from geomlib.mesh_io._text import (
    _LEADING_WS,
    _WS,
    Faces,
    PathLike,
    _check_finite_rows,
    _faces_for_writing,
    _float_strings,
    _fromstring,
    _parse_float_lines,
    _ragged_to_faces,
    _read_bytes,
    _Rows,
    _Source,
    _take_columns,
    _TextFile,
    _token_layout,
    _triangulate,
    _write_text,
    _writer_inputs,
)
from geomlib.validate import MeshError, as_array, as_vertices

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
    FileNotFoundError, MeshError
        As in :func:`~geomlib.mesh_io.read_mesh`.
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
    # A sign must precede a digit: NumPy would read a lone '+' or '-' as 0 (other bad tokens make
    # NumPy stop early, which the count check below catches).
    sign = np.flatnonzero((b == 43) | (b == 45))
    nxt = b[np.minimum(sign + 1, len(b) - 1)]
    lone = sign[(sign + 1 >= len(b)) | (nxt < 48) | (nxt > 57)]
    code[token_id[lone]] = -1
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
    path, V, F
        As in :func:`~geomlib.mesh_io.write_mesh`.
    UV : (t, 2) array_like of float, optional
        Texture coordinates, written as ``vt`` lines.
    N : (r, 3) array_like of float, optional
        Normals, written as ``vn`` lines.
    face_uv, face_normal : same structure as ``F``, optional
        0-based indices into ``UV`` / ``N`` per face corner. When omitted and ``UV`` (``N``)
        has one row per vertex, the vertex indices are used (per-vertex attributes).
    colors : (n, 3) array_like of float, optional
        Per-vertex colours appended to the ``v`` lines (``v x y z r g b``).
    precision
        As in :func:`~geomlib.mesh_io.write_mesh`.

    Raises
    ------
    MeshError
        Wrong shapes, out-of-range indices, or attribute indices that do not match ``F``.
    """
    where = "write_obj"
    V, idx, off, precision = _writer_inputs(V, F, precision, where)
    n = len(V)
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
