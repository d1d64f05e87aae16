"""OFF (and COFF, NOFF, ...): reader and writer."""

from __future__ import annotations

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
    _Source,
    _take_columns,
    _TextFile,
    _write_text,
    _writer_inputs,
)

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
    FileNotFoundError, MeshError
        As in :func:`~geomlib.mesh_io.read_mesh`.
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
    path, V, F, precision
        As in :func:`~geomlib.mesh_io.write_mesh`.
    """
    V, idx, off, precision = _writer_inputs(V, F, precision, "write_off")
    head = f"OFF\n{len(V)} {len(off) - 1} 0\n"
    _write_text(
        path, head + ("%s %s %s\n" * len(V)) % tuple(_float_strings(V, precision)) + _counted_face_lines(idx, off)
    )
