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

One module per format (:mod:`.obj`, :mod:`.off`, :mod:`.ply`) on shared text helpers (:mod:`._text`).

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

import numpy as np

from geomlib import topology
from geomlib.mesh_io._text import MESH_EXTENSIONS, Faces, PathLike, _ext, _triangulate, check_regular_file
from geomlib.mesh_io.obj import ObjData, _read_obj, read_obj, write_obj
from geomlib.mesh_io.off import _read_off, read_off, write_off
from geomlib.mesh_io.ply import PlyData, _read_ply, read_ply, write_ply
from geomlib.validate import MeshError

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
        Unsupported extension or malformed file: the message names the file, the line (text
        formats) and the problem.
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
        0-based faces (triangles, quads or mixed polygons, any sizes >= 3).
    **options
        Passed to :func:`write_obj`, :func:`write_off` or :func:`write_ply`
        (e.g. ``UV=``, ``N=``, ``precision=``, ``format="ascii"``). Every writer takes
        ``precision`` (int, optional): significant digits of the numbers written; default the
        shortest text that reads back exactly.

    Raises
    ------
    MeshError
        Unsupported extension, or bad arrays (the message names the argument and the problem).
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
