"""Input validation shared by every public geomlib function and every lab entry point.

One rule: bad input raises :class:`MeshError` (a ``ValueError``) whose message names the
problem *and the place* (which row, which face, which edge), prefixed with the name of the
function that was called, so a student reading it knows what to fix.

Examples
--------
>>> import numpy as np
>>> from geomlib.validate import check_mesh
>>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0.0]])
>>> check_mesh(V, [[0, 1, 3]], where="loop_subdivide")
Traceback (most recent call last):
...
geomlib.errors.MeshError: loop_subdivide: F: face 0 uses vertex 3, but V has only 3 vertices (valid indices 0..2)
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from contextvars import ContextVar

import numpy as np

from geomlib import topology
from geomlib.errors import MeshError, to_int64
from geomlib.errors import fmt_row as _fmt_row
from geomlib.errors import prefix as _prefix

__all__ = [
    "MeshError",
    "as_vertices",
    "as_faces",
    "as_array",
    "as_polygons",
    "as_image",
    "check_mesh",
    "checked",
    "check_polygon_mesh",
    "check_uv",
    "check_manifold",
    "check_int",
    "check_float",
    "check_choice",
]


def as_array(
    x,
    name: str,
    *,
    shape: Sequence[int | None] | None = None,
    dtype: type | np.dtype = np.float64,
    finite: bool = True,
    where: str | None = None,
) -> np.ndarray:
    """Convert ``x`` to a contiguous array of ``dtype`` and check its shape and values.

    Parameters
    ----------
    x : array_like
    name : str
        Name used in error messages (e.g. ``"UV"``).
    shape : sequence of int or None, optional
        Expected shape; ``None`` entries match any size. ``None`` skips the check.
    dtype : numpy dtype
        Target dtype. Integer targets reject non-integral floats.
    finite : bool
        For float targets, reject NaN and inf (naming the first bad row).
    where : str, optional
        Name of the calling function, prepended to messages.
    """
    p = _prefix(where)
    if x is None:
        raise MeshError(f"{p}{name} is missing (got None)")
    try:
        a = np.asarray(x)
    except ValueError:
        raise MeshError(f"{p}{name} is ragged (rows of different lengths); expected one numeric array") from None
    except Exception as e:
        raise MeshError(f"{p}{name} could not be read as an array ({e})") from None
    if a.dtype == object:
        raise MeshError(f"{p}{name} is ragged or holds non-numbers (dtype object); expected a numeric array")
    if shape is not None:
        exp = "(" + ", ".join("n" if s is None else str(s) for s in shape) + ")"
        if a.ndim != len(shape) or any(s is not None and s != d for s, d in zip(shape, a.shape, strict=False)):
            raise MeshError(f"{p}{name} has shape {a.shape}, expected {exp}")
    target = np.dtype(dtype)
    if target.kind in "iu":
        a = to_int64(a, name, where)
    else:
        if a.dtype.kind not in "biuf":
            raise MeshError(f"{p}{name} has dtype {a.dtype}, expected numbers")
        a = np.ascontiguousarray(a, dtype=target)
        if finite and a.size and not np.all(np.isfinite(a)):
            bad = ~np.isfinite(a)
            if a.ndim >= 2:
                r = int(np.flatnonzero(bad.reshape(a.shape[0], -1).any(axis=1))[0])
                raise MeshError(f"{p}{name}: row {r} has a non-finite value {_fmt_row(a[r].ravel())}")
            i = tuple(int(k) for k in np.argwhere(bad)[0])
            raise MeshError(f"{p}{name}: entry {i} is {a[i]}, expected a finite number")
    return a


def as_vertices(V, *, name: str = "V", dim: int = 3, where: str | None = None) -> np.ndarray:
    """Vertex positions as float64 ``(n, dim)``, finite."""
    return as_array(V, name, shape=(None, dim), dtype=np.float64, where=where)


def as_faces(
    F,
    n_vertices: int,
    *,
    name: str = "F",
    k: int | None = 3,
    allow_degenerate: bool = False,
    allow_duplicate: bool = False,
    where: str | None = None,
) -> np.ndarray:
    """Face indices as int64 ``(m, k)``, every index in ``0..n_vertices-1``.

    Degenerate faces (a repeated vertex) and duplicate faces (the same vertex set twice) are
    rejected unless allowed.
    """
    p = _prefix(where)
    raw = F if isinstance(F, np.ndarray) else None
    if raw is not None and raw.dtype.kind == "u":
        F = _unsigned_faces(raw, n_vertices, name, k, where)
    else:
        F = as_array(F, name, shape=(None, k) if k else (None, None), dtype=np.int64, where=where)
    if F.shape[0] == 0:
        return F
    if F.min() < 0:
        f = int(np.flatnonzero((F < 0).any(axis=1))[0])
        raise MeshError(f"{p}{name}: face {f} {_fmt_row(F[f])} has a negative index")
    if F.max() >= n_vertices:
        f = int(np.flatnonzero((F >= n_vertices).any(axis=1))[0])
        bad = int(F[f][F[f] >= n_vertices][0])
        raise MeshError(
            f"{p}{name}: face {f} uses vertex {bad}, but V has only {n_vertices} vertices "
            f"(valid indices 0..{n_vertices - 1})"
        )
    S = np.sort(F, axis=1)
    if not allow_degenerate:
        rep = (S[:, 1:] == S[:, :-1]).any(axis=1)
        if rep.any():
            f = int(np.flatnonzero(rep)[0])
            raise MeshError(f"{p}{name}: face {f} {_fmt_row(F[f])} is degenerate (repeats a vertex)")
    if not allow_duplicate:
        kk = S.shape[1]
        if kk and float(max(n_vertices, 1)) ** kk < 2.0**62:
            # one int64 key per sorted row: a single sort instead of a k-column lexsort (6x faster)
            key = S[:, 0].copy()
            for j in range(1, kk):
                key *= n_vertices
                key += S[:, j]
            order = np.argsort(key, kind="stable")
            ks = key[order]
            dup = np.flatnonzero(ks[1:] == ks[:-1])
        else:
            order = np.lexsort(S.T[::-1])
            Ss = S[order]
            dup = np.flatnonzero((Ss[1:] == Ss[:-1]).all(axis=1))
        if len(dup):
            pair = np.sort(order[[dup[0], dup[0] + 1]])
            raise MeshError(
                f"{p}{name}: faces {int(pair[0])} and {int(pair[1])} are duplicates "
                f"(both use vertices {_fmt_row(S[pair[0]])})"
            )
    return F


def _unsigned_faces(F: np.ndarray, n_vertices: int, name: str, k: int | None, where: str | None) -> np.ndarray:
    """Unsigned indices are compared before the int64 cast, so ``2**63`` is named, not wrapped to negative."""
    if F.ndim != 2 or (k is not None and F.shape[1] != k):
        raise MeshError(f"{_prefix(where)}{name} has shape {F.shape}, expected (n, {k if k else 'n'})")
    if F.size and F.max() >= n_vertices:
        f = int(np.flatnonzero((F >= n_vertices).any(axis=1))[0])
        bad = int(F[f][F[f] >= n_vertices][0])
        raise MeshError(
            f"{_prefix(where)}{name}: face {f} uses vertex {bad}, but V has only {n_vertices} vertices "
            f"(valid indices 0..{n_vertices - 1})"
        )
    return F.astype(np.int64)


def check_manifold(F, n_vertices: int, *, name: str = "F", where: str | None = None) -> None:
    """Raise unless the triangle or polygon mesh is edge- and vertex-manifold and consistently oriented.

    ``F`` is an ``(m, k)`` int array or a ``(indices, offsets)`` ragged pair (see :func:`as_polygons`).

    The checks are those of :func:`geomlib.topology.halfedge_mesh` with ``manifold=True``: one
    structure, one set of messages for every caller.
    """
    topology.halfedge_mesh(F, n_vertices, manifold=True, name=name, where=where)


#: Meshes a public entry point has validated, for the calls it makes (see :func:`checked`).
_CHECKED: ContextVar[tuple] = ContextVar("geomlib_checked_meshes", default=())


@contextmanager
def checked(V: np.ndarray, F: np.ndarray, *, manifold: bool = False, closed: bool = False) -> Iterator[None]:
    """Validate once per public entry: inside the block, ``check_mesh`` passes these arrays through.

    A public function validates its mesh with :func:`check_mesh`, then runs its internal calls
    (which are public functions too, and validate) inside ``with checked(V, F):``. There,
    ``check_mesh`` called on these very array objects returns them at once, unless it asks for
    more than was checked (``manifold``/``closed``). Other arrays, and calls outside the block,
    are validated as always.

    Examples
    --------
    >>> V, F = check_mesh(V, F, where="bake_vdm")  # doctest: +SKIP
    >>> with checked(V, F):  # doctest: +SKIP
    ...     UV = parameterize_square(V, F)  # its check_mesh(V, F) costs nothing now
    """
    token = _CHECKED.set((*_CHECKED.get(), (V, F, manifold, closed)))
    try:
        yield
    finally:
        _CHECKED.reset(token)


def check_mesh(
    V,
    F,
    *,
    where: str | None = None,
    manifold: bool = False,
    closed: bool = False,
    allow_degenerate: bool = False,
    allow_duplicate: bool = False,
    min_faces: int = 1,
    vname: str = "V",
    fname: str = "F",
) -> tuple[np.ndarray, np.ndarray]:
    """Validate a triangle mesh and return it as ``(V float64 (n, 3), F int64 (m, 3))``.

    Parameters
    ----------
    V, F : array_like
        Vertex positions and triangle indices.
    where : str, optional
        Name of the calling function, used as message prefix.
    manifold : bool
        Also require an edge- and vertex-manifold, consistently oriented mesh.
    closed : bool
        Also require no boundary edges.
    allow_degenerate, allow_duplicate : bool
        Accept faces that repeat a vertex / that repeat another face.
    min_faces : int
        Fewest faces accepted.
    vname, fname : str
        Names of the two arguments in messages (e.g. ``"V1"``, ``"F1"``).
    """
    for V0, F0, was_manifold, was_closed in _CHECKED.get():
        if (
            V is V0
            and F is F0
            and (was_manifold or not manifold)
            and (was_closed or not closed)
            and len(F) >= min_faces
        ):
            return V, F
    p = _prefix(where)
    V = as_vertices(V, name=vname, where=where)
    if F is not None and not isinstance(F, np.ndarray):
        try:
            F = np.asarray(F)
            shape_ok = F.ndim == 2 and F.dtype != object
        except Exception:
            shape_ok = False
        if not shape_ok:
            raise MeshError(f"{p}{fname} must be an (m, 3) integer array of triangles; got a ragged or polygonal list")
    if F is not None and F.ndim == 2 and F.shape[1] != 3:
        raise MeshError(
            f"{p}{fname} has shape {F.shape}: this function needs triangles (m, 3); triangulate polygon faces first"
        )
    F = as_faces(F, len(V), name=fname, where=where, allow_degenerate=allow_degenerate, allow_duplicate=allow_duplicate)
    if len(F) < min_faces:
        raise MeshError(f"{p}{fname} has {len(F)} faces, expected at least {min_faces}")
    if manifold or closed:
        H = topology.halfedge_mesh(F, len(V), manifold=manifold, checked=True, name="F", where=where)
        b = np.flatnonzero(H.edge_size[H.he_edge] == 1) if closed else ()
        if len(b):
            raise MeshError(
                f"{p}mesh has {len(b)} boundary edges (e.g. ({H.idx[b[0]]}, {H.idx[H.nxt[b[0]]]})); "
                f"expected a closed mesh"
            )
    return V, F


def as_polygons(
    faces, n_vertices: int, *, name: str = "faces", where: str | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Polygon faces as a ragged ``(indices, offsets)`` pair of int64 arrays.

    ``faces`` is an int ``(m, k)`` array, a list of index sequences of any lengths >= 3, or a
    ragged pair (see :func:`geomlib.topology.to_ragged`, which makes every check but the repeated
    vertex). Face ``f`` is ``indices[offsets[f]:offsets[f + 1]]``.
    """
    idx, off = topology.to_ragged(faces, n_vertices, name=name, where=where)
    if idx.size:  # a polygon that repeats a vertex is degenerate
        face_of = np.repeat(np.arange(len(off) - 1), np.diff(off))
        order = np.lexsort((idx, face_of))
        s_idx, s_face = idx[order], face_of[order]
        rep = (s_idx[1:] == s_idx[:-1]) & (s_face[1:] == s_face[:-1])
        if rep.any():
            f = int(s_face[1:][rep][0])
            raise MeshError(
                f"{_prefix(where)}{name}: face {f} {_fmt_row(idx[off[f] : off[f + 1]])} is degenerate "
                f"(repeats a vertex)"
            )
    return idx, off


def check_polygon_mesh(
    V, faces, *, where: str | None = None, manifold: bool = False
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Validate a polygon mesh; return ``(V, indices, offsets)`` (see :func:`as_polygons`)."""
    V = as_vertices(V, where=where)
    idx, off = as_polygons(faces, len(V), where=where)
    if len(off) < 2:
        raise MeshError(f"{_prefix(where)}faces is empty, expected at least one polygon")
    if manifold:
        check_manifold((idx, off), len(V), name="faces", where=where)
    return V, idx, off


#: UV values this far outside [0, 1] still count as inside (round-off of exporters).
UV_SLACK = 1e-9


def check_uv(UV, n: int, where: str | None = None, *, in_range: bool = False, name: str = "UV") -> np.ndarray:
    """Texture coordinates ``(n, 2)`` float64, one ``(u, v)`` row per vertex.

    Parameters
    ----------
    UV : (n, 2) array_like
    n : int
        Number of vertices.
    where, name : str
        Function and argument names for error messages.
    in_range : bool
        Also require every row inside the texture square ``[0, 1]^2`` (up to :data:`UV_SLACK`).
    """
    p = _prefix(where)
    if UV is None:
        raise MeshError(f"{p}{name} is missing; this function needs texture coordinates, one (u, v) row per vertex")
    UV = as_array(UV, name, shape=(None, 2), where=where)
    if len(UV) != n:
        raise MeshError(f"{p}{name} has {len(UV)} rows but V has {n}; expected one (u, v) per vertex")
    if in_range:
        bad = ((UV < -UV_SLACK) | (UV > 1 + UV_SLACK)).any(axis=1)
        if bad.any():
            r = int(np.flatnonzero(bad)[0])
            raise MeshError(
                f"{p}{name} row {r} is ({UV[r, 0]:.6g}, {UV[r, 1]:.6g}), outside the texture square [0, 1]^2 "
                f"({int(bad.sum())} rows are out of range)"
            )
    return UV


def check_int(
    value, name: str, *, minimum: int | None = None, maximum: int | None = None, where: str | None = None
) -> int:
    """An integer parameter (bools and non-integral floats rejected)."""
    p = _prefix(where)
    if isinstance(value, bool) or not isinstance(value, int | np.integer):
        raise MeshError(f"{p}{name} must be an integer, got {value!r} ({type(value).__name__})")
    value = int(value)
    if minimum is not None and value < minimum:
        raise MeshError(f"{p}{name} must be >= {minimum}, got {value}")
    if maximum is not None and value > maximum:
        raise MeshError(f"{p}{name} must be <= {maximum}, got {value}")
    return value


def check_float(
    value,
    name: str,
    *,
    minimum: float | None = None,
    maximum: float | None = None,
    positive: bool = False,
    where: str | None = None,
) -> float:
    """A finite real parameter within optional bounds (``positive``: strictly greater than 0)."""
    p = _prefix(where)
    if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating):
        raise MeshError(f"{p}{name} must be a number, got {value!r} ({type(value).__name__})")
    value = float(value)
    if not np.isfinite(value):
        raise MeshError(f"{p}{name} must be finite, got {value}")
    if positive and value <= 0:
        raise MeshError(f"{p}{name} must be > 0, got {value}")
    if minimum is not None and value < minimum:
        raise MeshError(f"{p}{name} must be >= {minimum}, got {value}")
    if maximum is not None and value > maximum:
        raise MeshError(f"{p}{name} must be <= {maximum}, got {value}")
    return value


def check_choice(value, name: str, choices: Sequence[str], *, where: str | None = None) -> str:
    """One of a fixed set of string options."""
    if not isinstance(value, str) or value not in choices:
        raise MeshError(f"{_prefix(where)}{name} must be one of {', '.join(map(repr, choices))}; got {value!r}")
    return value


def as_image(
    img,
    name: str = "image",
    *,
    channels: int | Sequence[int] | None = None,
    size: tuple[int, int] | None = None,
    square: bool = False,
    dtype: type | np.dtype | None = None,
    where: str | None = None,
) -> np.ndarray:
    """Check an image array ``(h, w)`` or ``(h, w, c)``.

    Parameters
    ----------
    channels : int or sequence of int, optional
        Allowed channel counts; a 2-D array counts as 1 channel. Default 1 to 4 (grey, grey +
        alpha, RGB, RGBA); pass the counts explicitly for multi-channel data maps.
    size : (h, w), optional
        Required height and width.
    square : bool
        Require ``h == w``.
    dtype : dtype, optional
        Convert to this dtype (float targets must be finite).

    Float images must be finite (a NaN or infinite pixel is reported with its position), and
    complex or non-numeric arrays are refused.
    """
    p = _prefix(where)
    if img is None:
        raise MeshError(f"{p}{name} is missing (got None)")
    a = np.asarray(img)
    if a.ndim not in (2, 3) or a.dtype == object:
        raise MeshError(f"{p}{name} has shape {a.shape}; expected an image (h, w) or (h, w, c)")
    if a.dtype.kind not in "biuf":
        raise MeshError(f"{p}{name} has dtype {a.dtype}; expected numbers (bool, integer or float)")
    c = 1 if a.ndim == 2 else a.shape[2]
    allowed = (1, 2, 3, 4) if channels is None else (channels,) if isinstance(channels, int) else tuple(channels)
    if c not in allowed:
        raise MeshError(f"{p}{name} has {c} channel(s) (shape {a.shape}); expected {' or '.join(map(str, allowed))}")
    if a.shape[0] == 0 or a.shape[1] == 0:
        raise MeshError(f"{p}{name} is empty (shape {a.shape})")
    if size is not None and tuple(a.shape[:2]) != tuple(size):
        raise MeshError(f"{p}{name} is {a.shape[0]}x{a.shape[1]} pixels; expected {size[0]}x{size[1]}")
    if square and a.shape[0] != a.shape[1]:
        raise MeshError(f"{p}{name} is {a.shape[0]}x{a.shape[1]} pixels; expected a square image")
    if a.dtype.kind == "f" and a.size and not np.isfinite(a).all():
        px = tuple(int(i) for i in np.argwhere(~np.isfinite(a))[0])
        raise MeshError(f"{p}{name} has a non-finite value ({a[px]}) at pixel {px[:2]}; images must be finite")
    if dtype is not None:
        a = as_array(a, name, dtype=dtype, where=where)
    return a
