"""The two entry points, :func:`render` and :func:`render_polygons`, and the draw pipeline.

``_draw`` runs the stages, each in its own module: check the options (:mod:`.options`), place the
camera (:mod:`.cameras`), build the scene in a normalised frame (:mod:`.scene`), add lights
(:mod:`.lights`), render on the cached GL context (:mod:`.context`), draw the wireframe and point
overlays (:mod:`.overlay`) and average the supersampled image down.
"""

from __future__ import annotations

import numpy as np

from geomlib import topology
from geomlib.halfedge import next_corners
from geomlib.render.cameras import resolve_camera
from geomlib.render.context import import_pyrender, inherited_context, offscreen_renderer
from geomlib.render.fresh import render_in_fresh_process
from geomlib.render.lights import add_lights, light_specs
from geomlib.render.options import RenderOptions, _as_rgb, _as_texture, check_options
from geomlib.render.overlay import auto_wire_opacity, overlay
from geomlib.render.scene import Surface, add_floor, add_surface, normalised_frame
from geomlib.render.shading import vertex_normals
from geomlib.validate import MeshError, as_array, check_choice, check_float, check_mesh, check_polygon_mesh

__all__ = ["render", "render_polygons"]

_RETURNS = """
    Returns
    -------
    (height, width, 3) uint8
        The image.

    Raises
    ------
    MeshError
        On invalid meshes, arrays or options.
    RuntimeError
        When no headless OpenGL platform works (the message names the fix).
"""


def render(V, F, options: RenderOptions | None = None, /, **overrides) -> np.ndarray:
    """Render a triangle mesh to an RGB image (headless, deterministic).

    Parameters
    ----------
    V : (n, 3) array_like
        Vertex positions.
    F : (m, 3) int array_like
        Triangles (degenerate and duplicate faces are drawn as they are).
    options : RenderOptions, optional
        How to draw (defaults: :class:`RenderOptions`).
    **overrides
        Any field of :class:`RenderOptions` by name, e.g. ``wireframe=True, size=(320, 240)``.
    """
    if inherited_context():  # forked after OpenGL was used: draw in a fresh interpreter (see .fresh)
        return render_in_fresh_process("render", V, F, options, overrides)
    where = "render"
    o = RenderOptions.build(options, overrides, where)
    V, F = check_mesh(V, F, where=where, allow_degenerate=True, allow_duplicate=True)
    C, TC, UV, TEX, N, hp = _check_attributes(V, len(F), o, where=where)
    tri_n = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    vn = N if N is not None else vertex_normals(len(V), F, tri_n)
    surface = Surface(
        V=V,
        T=F,
        tri_normals=tri_n,
        vert_normals=vn,
        user_normals=N is not None,
        edges=topology.unique_edges(F) if o.wireframe else None,
        colors=C,
        tri_colors=TC,
        uv=UV,
        texture=TEX,
        highlight_points=hp,
    )
    return _draw(surface, o, where)


def render_polygons(V, faces, options: RenderOptions | None = None, /, **overrides) -> np.ndarray:
    """Render a polygon mesh; shading uses a fan triangulation, the wireframe the true polygon edges.

    Parameters
    ----------
    V : (n, 3) array_like
        Vertex positions.
    faces : (m, k) int array_like, list of index sequences, or ``(indices, offsets)``
        Polygons with at least 3 corners each (see :func:`geomlib.validate.as_polygons`).
    options, **overrides
        As for :func:`render`; ``face_colors`` has one row per polygon and flat shading uses one
        (Newell) normal per polygon.
    """
    if inherited_context():
        return render_in_fresh_process("render_polygons", V, faces, options, overrides)
    where = "render_polygons"
    o = RenderOptions.build(options, overrides, where)
    if isinstance(faces, tuple) and len(faces) == 2 and all(isinstance(a, np.ndarray) and a.ndim == 1 for a in faces):
        faces = [faces[0][a:b] for a, b in zip(faces[1][:-1], faces[1][1:], strict=True)]
    V, idx, off = check_polygon_mesh(V, faces, where=where)
    m = len(off) - 1
    C, PC, UV, TEX, N, hp = _check_attributes(V, m, o, where=where)
    T, src = topology.triangulate_polygons((idx, off))
    # Newell normal of each polygon (twice its vector area), robust for non-planar polygons.
    lens = np.diff(off)
    nxt = next_corners(off)  # the one half-edge convention (geomlib.halfedge)
    a, b = V[idx], V[idx[nxt]]
    cr = np.cross(a, b)
    poly_n = np.add.reduceat(cr, off[:-1], axis=0) if m else np.zeros((0, 3))
    user_normals = N is not None
    if N is None:
        face_of = np.repeat(np.arange(m), lens)
        N = np.stack([np.bincount(idx, weights=poly_n[face_of, c], minlength=len(V)) for c in range(3)], axis=1)
    surface = Surface(
        V=V,
        T=T,
        tri_normals=poly_n[src] / np.maximum(lens - 2, 1)[src, None],  # each polygon weighs its area once
        vert_normals=N,
        user_normals=user_normals,
        edges=topology.unique_edges((idx, off)) if o.wireframe else None,
        colors=C,
        tri_colors=PC[src] if PC is not None else None,
        uv=UV,
        texture=TEX,
        highlight_points=hp,
    )
    return _draw(surface, o, where)


render.__doc__ += _RETURNS
render_polygons.__doc__ += _RETURNS


def _draw(s: Surface, o: RenderOptions, where: str) -> np.ndarray:
    chk = check_options(o, where)
    lines = None
    if o.highlight_lines is not None:
        lines = as_array(o.highlight_lines, "highlight_lines", shape=(None, 2, 3), where=where)
        line_rgb = _as_rgb(o.line_color, "line_color", where)
        line_px = check_float(o.line_width, "line_width", positive=True, where=where)
    if isinstance(o.light, str):
        check_choice(o.light, "light", ("directional", "spot"), where=where)
        specs = None
    else:
        specs = light_specs(o.light, where)
    w, h, ss = chk.width, chk.height, chk.ss
    W, H = w * ss, h * ss
    pose = resolve_camera(
        o.camera, s.V, fov_deg=o.fov_deg, size=(w, h), zoom=o.zoom, up_axis=o.up_axis, forward=o.forward, where=where
    )
    fr = normalised_frame(s.V, pose, floor=bool(o.floor), up_vec=chk.up_vec)

    pyrender = import_pyrender()
    scene = pyrender.Scene(bg_color=[*map(float, chk.background), 1.0], ambient_light=[chk.ambient] * 3)
    add_surface(
        scene, pyrender, s, fr.V, fr.fwd, smooth=bool(o.smooth), flat=bool(o.flat), crease_deg=chk.crease_deg, chk=chk
    )
    if o.floor:
        add_floor(scene, pyrender, fr, chk.up_vec, flat=bool(o.flat))
    scene.add(pyrender.PerspectiveCamera(yfov=chk.fov, znear=fr.znear, zfar=fr.zfar, aspectRatio=w / h), pose=fr.pose)
    flags = add_lights(
        scene,
        pyrender,
        o.light,
        specs,
        fr.pose,
        center=fr.center,
        c0=fr.c0,
        s0=fr.s0,
        shadows=bool(o.shadows),
        where=where,
    )
    if o.flat:
        flags |= pyrender.RenderFlags.FLAT

    col, depth = offscreen_renderer(W, H).render(scene, flags=flags)
    col = np.asarray(col[:, :, :3])

    edges, hp = s.edges, s.highlight_points
    wire_opacity = chk.wire_opacity
    if wire_opacity is None:
        wire_opacity = auto_wire_opacity(fr.V, edges, (w, h), zoom=o.zoom) if edges is not None else 0.0
    if (edges is not None and chk.edge_width > 0 and wire_opacity > 0) or (hp is not None and chk.point_radius > 0):
        img = overlay(
            col,
            np.asarray(depth),
            fr.pose,
            chk.fov,
            fr.znear,
            fr.diag,
            V=fr.V,
            edges=edges if chk.edge_width > 0 else None,
            wire_color=chk.wire_rgb,
            line_px=chk.edge_width * ss,
            wire_opacity=wire_opacity,
            points=hp,
            point_color=chk.point_rgb,
            point_px=2.0 * chk.point_radius * ss,
        )
    else:
        img = col.astype(np.float32)
    if lines is not None and len(lines):
        X = (lines.reshape(-1, 3) - fr.c0) / fr.s0  # into the normalised frame, as the mesh
        img = overlay(
            img, np.asarray(depth), fr.pose, chk.fov, fr.znear, fr.diag, V=X,
            edges=np.arange(len(X)).reshape(-1, 2), wire_color=line_rgb, line_px=line_px * ss, wire_opacity=1.0,
            points=None, point_color=chk.point_rgb, point_px=0.0,
        )  # fmt: skip
    if ss > 1:  # box filter: sum the ss*ss sub-pixel grids
        acc = np.zeros((h, w, 3), dtype=np.float32)
        for i in range(ss):
            for j in range(ss):
                acc += img[i::ss, j::ss]
        img = acc / (ss * ss)
    return np.clip(np.round(img), 0, 255).astype(np.uint8)


def _check_attributes(V, m, o: RenderOptions, *, where):
    """Validate the optional per-vertex / per-face arrays shared by render and render_polygons."""
    colors, face_colors, uv, texture, normals = o.colors, o.face_colors, o.uv, o.texture, o.normals
    highlight_points = o.highlight_points
    n = len(V)
    C = _as_rgb(colors, "colors", where, n=n) if colors is not None else None
    FC = _as_rgb(face_colors, "face_colors", where, n=m, per="face") if face_colors is not None else None
    if (uv is None) != (texture is None):
        raise MeshError(f"{where}: uv and texture go together; got {'uv' if uv is not None else 'texture'} only")
    UV = TEX = None
    if uv is not None:
        UV = as_array(uv, "uv", shape=(None, 2), where=where)
        if len(UV) != n:
            raise MeshError(f"{where}: uv has {len(UV)} rows, expected {n} (one texture coordinate per vertex)")
        TEX = _as_texture(texture, where)
    N = None
    if normals is not None:
        N = as_array(normals, "normals", shape=(None, 3), where=where)
        if len(N) != n:
            raise MeshError(f"{where}: normals has {len(N)} rows, expected {n} (one normal per vertex)")
        zero = np.linalg.norm(N, axis=1) == 0
        if zero.any():
            raise MeshError(f"{where}: normals: row {int(np.flatnonzero(zero)[0])} is the zero vector")
    hp = None
    if highlight_points is not None:
        hp = as_array(highlight_points, "highlight_points", dtype=np.int64, where=where).ravel()
        if hp.size and (hp.min() < 0 or hp.max() >= n):
            bad = int(hp[(hp < 0) | (hp >= n)][0])
            raise MeshError(f"{where}: highlight_points has vertex index {bad}, valid indices are 0..{n - 1}")
    if np.ndim(o.point_color) == 2:  # one colour per dot
        if hp is None:
            raise MeshError(f"{where}: point_color gives one colour per dot, but highlight_points is not given")
        _as_rgb(o.point_color, "point_color", where, n=len(hp), per="entry of highlight_points")
    return C, FC, UV, TEX, N, hp
