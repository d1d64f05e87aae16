"""Turn a mesh in 3D (``geomlib.view``, ``geomlib view FILE``): a pyvista window, a notebook widget, or a self-contained HTML page.

``geomlib.view(V, F, scalars=...)`` (this module's :func:`view`; the module is not called
``view`` so that the package attribute stays the function) and ``geomlib view FILE`` pick what the place allows:

- in a Jupyter notebook it returns a widget (an ``<iframe>`` holding the HTML page below), which
  the notebook displays and you turn with the mouse;
- where a display exists it opens an interactive pyvista window;
- with ``html="out.html"`` (``--html out.html``) it writes one HTML file that works offline.

Why our own page instead of pyvista's ``export_html``: since pyvista 0.49 that method forwards to
the separate ``trame-pyvista`` package, which pulls in the trame web-application stack (trame,
trame-server, trame-client, trame-vtk, wslink, aiohttp) to write a static page of a few MB of
vtk.js. A mesh viewer needs far less: the page below is ~8 kB of plain WebGL2 (flat shading from
screen-space derivatives, orbit/zoom/pan, edges, a colour bar) plus the mesh as base64 arrays. It
loads no script, font or image from anywhere, so it works offline and in a sandboxed iframe.
"""

from __future__ import annotations

import base64
import html as _html
import json
import os
import sys
from pathlib import Path

import numpy as np

from geomlib import topology
from geomlib.validate import MeshError, as_array

__all__ = ["view", "view_file", "html_page", "write_html", "has_display", "in_notebook"]


# --------------------------------------------------------------------------------------------
# Where are we?
# --------------------------------------------------------------------------------------------


def in_notebook() -> bool:
    """True inside a Jupyter kernel (where a returned widget is displayed)."""
    ip = sys.modules.get("IPython")
    if ip is None:
        return False
    shell = ip.get_ipython() if hasattr(ip, "get_ipython") else None
    return shell is not None and type(shell).__name__ == "ZMQInteractiveShell"


def has_display() -> bool:
    """True when a desktop window can open (X11/Wayland on Linux; always on macOS and Windows)."""
    if sys.platform in ("darwin", "win32"):
        return True
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


# --------------------------------------------------------------------------------------------
# Mesh preparation (shared by the page and the window)
# --------------------------------------------------------------------------------------------


def _prepare(V, faces, scalars, where: str):
    """Triangles, polygon edges and per-vertex scalars (face scalars are spread to face corners)."""
    V = as_array(V, "V", shape=(None, 3), dtype=np.float64, where=where)
    idx, off = topology.to_ragged(faces)
    if len(idx) and (idx.min() < 0 or idx.max() >= len(V)):
        bad = int(np.flatnonzero((idx < 0) | (idx >= len(V)))[0])
        face = int(np.searchsorted(off, bad, side="right") - 1)
        raise MeshError(f"{where}: face {face} uses vertex {int(idx[bad])}, but V has only {len(V)} vertices")
    if (np.diff(off) < 3).any():
        raise MeshError(f"{where}: face {int(np.flatnonzero(np.diff(off) < 3)[0])} has fewer than 3 corners")
    T, src = topology.triangulate_polygons((idx, off))
    E = topology.unique_edges((idx, off))
    s = None
    if scalars is not None:
        s = np.asarray(scalars, dtype=np.float64).ravel()
        m = len(off) - 1
        if len(s) == len(V):
            pass
        elif len(s) == m:
            # One value per face: give every triangle its own three corners so colours do not blend.
            s = np.repeat(s[src], 3)
            V = V[T.ravel()]
            T = np.arange(len(V), dtype=np.int64).reshape(-1, 3)
        else:
            raise MeshError(
                f"{where}: scalars has {len(s)} values; expected one per vertex ({len(V)}) or per face ({m})"
            )
        if not np.isfinite(s).all():
            raise MeshError(f"{where}: scalars has NaN or infinite values")
    return V, T, E, s


def _colors(s: np.ndarray, cmap: str, clim):
    from geomlib.plot import heat_colors

    lo, hi = (float(s.min()), float(s.max())) if clim is None else (float(clim[0]), float(clim[1]))
    if hi <= lo:
        hi = lo + 1.0
    to8 = lambda c: np.round(c * 255).astype(np.uint8)
    ramp = to8(heat_colors(np.linspace(lo, hi, 64), vmin=lo, vmax=hi, cmap=cmap))
    return to8(heat_colors(s, vmin=lo, vmax=hi, cmap=cmap)), ramp, lo, hi


def _tick(x: float, lo: float, hi: float) -> str:
    """A colour-bar label: 3 significant digits, and 0 for a value within 0.1% of the range of zero."""
    if abs(x) <= 1e-3 * max(abs(lo), abs(hi)):
        return "0"
    return f"{x:.3g}"


def _b64(a: np.ndarray, dtype) -> str:
    return base64.b64encode(np.ascontiguousarray(a, dtype=np.dtype(dtype).newbyteorder("<")).tobytes()).decode("ascii")


# --------------------------------------------------------------------------------------------
# The HTML page
# --------------------------------------------------------------------------------------------

_PAGE = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>__TITLE__</title>
<style>
html, body { margin: 0; height: 100%; background: #fff; font-family: "DejaVu Sans", Arial, sans-serif; overflow: hidden; }
canvas { display: block; width: 100%; height: 100%; touch-action: none; cursor: grab; }
#hud { position: absolute; left: 10px; top: 8px; font-size: 13px; color: #333; pointer-events: none; }
#hud b { font-size: 14px; }
#bar { position: absolute; right: 12px; top: 12px; width: 18px; height: 45%; border: 1px solid #555; }
.tick { position: absolute; right: 36px; font-size: 12px; color: #222; }
#err { position: absolute; left: 10px; bottom: 40px; color: #b00; font-size: 13px; }
button { position: absolute; left: 10px; bottom: 10px; font-size: 12px; }
</style></head>
<body data-status="loading">
<canvas id="c"></canvas>
<div id="hud"><b>__TITLE__</b><br>__INFO__<br>drag: turn · shift/right-drag: move · wheel: zoom · e: edges · r: reset</div>
__BAR__
<button id="edges" type="button">edges on/off</button>
<div id="err"></div>
<script>
"use strict";
window.addEventListener("error", function (e) {
  document.body.dataset.status = "error: " + e.message;
  document.getElementById("err").textContent = "viewer error: " + e.message;
});
const DATA = __DATA__;
function decode(s, Type) {
  const bin = atob(s), bytes = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
  return new Type(bytes.buffer);
}
const P = decode(DATA.positions, Float32Array), T = decode(DATA.triangles, Uint32Array);
const E = decode(DATA.edges, Uint32Array), C = DATA.colors ? decode(DATA.colors, Uint8Array) : null;
const canvas = document.getElementById("c");
const gl = canvas.getContext("webgl2", { antialias: true });
if (!gl) throw new Error("WebGL2 is not available in this browser");

function shader(type, src) {
  const s = gl.createShader(type); gl.shaderSource(s, src); gl.compileShader(s);
  if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
  return s;
}
function program(vs, fs) {
  const p = gl.createProgram();
  gl.attachShader(p, shader(gl.VERTEX_SHADER, vs)); gl.attachShader(p, shader(gl.FRAGMENT_SHADER, fs));
  gl.linkProgram(p);
  if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(p));
  return p;
}
const VS = `#version 300 es
in vec3 pos; in vec3 col; uniform mat4 mv, proj; uniform float lift; out vec3 vpos; out vec3 vcol;
void main() { vec4 p = mv * vec4(pos, 1.0); vpos = p.xyz; vcol = col; gl_Position = proj * p;
  gl_Position.z -= lift * gl_Position.w; }`;
// Flat shading: the face normal from screen-space derivatives of the view-space position, so the
// page needs no normals and shows the true facets.
const FS = `#version 300 es
precision highp float; in vec3 vpos; in vec3 vcol; uniform float lit; out vec4 frag;
void main() { vec3 n = normalize(cross(dFdx(vpos), dFdy(vpos)));
  vec3 l = normalize(vec3(0.4, 0.6, 1.0)); float d = abs(dot(n, l));
  vec3 c = lit > 0.5 ? vcol * (0.3 + 0.7 * d) + vec3(0.12) * pow(d, 24.0) : vcol;
  frag = vec4(c, 1.0); }`;
const prog = program(VS, FS);
const loc = { pos: gl.getAttribLocation(prog, "pos"), col: gl.getAttribLocation(prog, "col"),
  mv: gl.getUniformLocation(prog, "mv"), proj: gl.getUniformLocation(prog, "proj"),
  lift: gl.getUniformLocation(prog, "lift"), lit: gl.getUniformLocation(prog, "lit") };
function buffer(target, data) { const b = gl.createBuffer(); gl.bindBuffer(target, b); gl.bufferData(target, data, gl.STATIC_DRAW); return b; }
const nv = P.length / 3;
let colors = new Float32Array(nv * 3);
if (C) { for (let i = 0; i < nv * 3; i++) colors[i] = C[i] / 255; }
else { for (let i = 0; i < nv; i++) colors.set([0.62, 0.72, 0.86], 3 * i); }
const posBuf = buffer(gl.ARRAY_BUFFER, P), colBuf = buffer(gl.ARRAY_BUFFER, colors);
const triBuf = buffer(gl.ELEMENT_ARRAY_BUFFER, T), edgeBuf = buffer(gl.ELEMENT_ARRAY_BUFFER, E);
const black = buffer(gl.ARRAY_BUFFER, new Float32Array(nv * 3).fill(0.12));

// Camera: orbit around the bounding-box centre, distance from the bounding-sphere radius.
let lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
for (let i = 0; i < nv; i++) for (let k = 0; k < 3; k++) { lo[k] = Math.min(lo[k], P[3 * i + k]); hi[k] = Math.max(hi[k], P[3 * i + k]); }
const centre = [0, 1, 2].map(k => (lo[k] + hi[k]) / 2);
const radius = Math.max(1e-9, 0.5 * Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]));
const UP = DATA.up;  // 1 = y up, 2 = z up
let yaw, pitch, dist, pan, showEdges = DATA.edgesOn;
function reset() { yaw = 0.6; pitch = 0.35; dist = 2.6 * radius; pan = [0, 0]; }
reset();
function mul(a, b) { const r = new Float32Array(16);
  for (let i = 0; i < 4; i++) for (let j = 0; j < 4; j++) { let s = 0; for (let k = 0; k < 4; k++) s += a[k * 4 + j] * b[i * 4 + k]; r[i * 4 + j] = s; }
  return r; }
function rotX(t) { const c = Math.cos(t), s = Math.sin(t); return new Float32Array([1,0,0,0, 0,c,s,0, 0,-s,c,0, 0,0,0,1]); }
function rotY(t) { const c = Math.cos(t), s = Math.sin(t); return new Float32Array([c,0,-s,0, 0,1,0,0, s,0,c,0, 0,0,0,1]); }
function translate(x, y, z) { return new Float32Array([1,0,0,0, 0,1,0,0, 0,0,1,0, x,y,z,1]); }
// z-up meshes: turn z onto y first, so the orbit keeps the mesh's up direction up.
const zup = new Float32Array([1,0,0,0, 0,0,-1,0, 0,1,0,0, 0,0,0,1]);
function draw() {
  const w = canvas.clientWidth, h = canvas.clientHeight, dpr = window.devicePixelRatio || 1;
  if (canvas.width !== Math.round(w * dpr) || canvas.height !== Math.round(h * dpr)) { canvas.width = Math.round(w * dpr); canvas.height = Math.round(h * dpr); }
  gl.viewport(0, 0, canvas.width, canvas.height);
  gl.clearColor(1, 1, 1, 1); gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT); gl.enable(gl.DEPTH_TEST);
  let mv = translate(-centre[0], -centre[1], -centre[2]);
  if (UP === 2) mv = mul(zup, mv);
  mv = mul(rotY(-yaw), mv); mv = mul(rotX(pitch), mv); mv = mul(translate(pan[0], pan[1], -dist), mv);
  const f = 1 / Math.tan(0.5 * 0.6), a = canvas.width / Math.max(1, canvas.height);
  const near = Math.max(1e-6, dist - 2 * radius, dist * 0.01), far = dist + 2 * radius;
  const proj = new Float32Array([f / a,0,0,0, 0,f,0,0, 0,0,(far + near) / (near - far),-1, 0,0,2 * far * near / (near - far),0]);
  gl.useProgram(prog); gl.uniformMatrix4fv(loc.mv, false, mv); gl.uniformMatrix4fv(loc.proj, false, proj);
  gl.bindBuffer(gl.ARRAY_BUFFER, posBuf); gl.enableVertexAttribArray(loc.pos); gl.vertexAttribPointer(loc.pos, 3, gl.FLOAT, false, 0, 0);
  gl.bindBuffer(gl.ARRAY_BUFFER, colBuf); gl.enableVertexAttribArray(loc.col); gl.vertexAttribPointer(loc.col, 3, gl.FLOAT, false, 0, 0);
  gl.uniform1f(loc.lift, 0); gl.uniform1f(loc.lit, 1);
  gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, triBuf); gl.drawElements(gl.TRIANGLES, T.length, gl.UNSIGNED_INT, 0);
  if (showEdges && E.length) {
    gl.bindBuffer(gl.ARRAY_BUFFER, black); gl.vertexAttribPointer(loc.col, 3, gl.FLOAT, false, 0, 0);
    gl.uniform1f(loc.lift, 2e-4 * radius / dist * 50); gl.uniform1f(loc.lit, 0);
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, edgeBuf); gl.drawElements(gl.LINES, E.length, gl.UNSIGNED_INT, 0);
  }
  document.body.dataset.status = "ok";
}
let drag = null;
canvas.addEventListener("contextmenu", e => e.preventDefault());
canvas.addEventListener("pointerdown", e => { drag = { x: e.clientX, y: e.clientY, pan: e.shiftKey || e.button === 2 }; canvas.setPointerCapture(e.pointerId); });
canvas.addEventListener("pointerup", () => { drag = null; });
canvas.addEventListener("pointermove", e => {
  if (!drag) return;
  const dx = e.clientX - drag.x, dy = e.clientY - drag.y; drag.x = e.clientX; drag.y = e.clientY;
  if (drag.pan) { const s = dist / Math.max(1, canvas.clientHeight); pan[0] += dx * s; pan[1] -= dy * s; }
  else { yaw -= dx * 0.01; pitch = Math.max(-1.55, Math.min(1.55, pitch + dy * 0.01)); }
  requestAnimationFrame(draw);
});
canvas.addEventListener("wheel", e => { e.preventDefault(); dist *= Math.exp(e.deltaY * 0.001); requestAnimationFrame(draw); }, { passive: false });
window.addEventListener("keydown", e => { if (e.key === "e") { showEdges = !showEdges; draw(); } if (e.key === "r") { reset(); draw(); } });
document.getElementById("edges").addEventListener("click", () => { showEdges = !showEdges; draw(); });
window.addEventListener("resize", draw);
draw();
</script>
</body></html>
"""


def html_page(
    V,
    faces,
    scalars=None,
    *,
    title: str = "mesh",
    cmap: str = "viridis",
    clim=None,
    edges: bool | None = None,
    up: str = "y",
    scalar_name: str = "",
) -> str:
    """The self-contained interactive viewer page of a mesh, as a string.

    Parameters
    ----------
    V : (n, 3) float array
        Vertex positions.
    faces : (m, k) int array, list of polygons, or ``(indices, offsets)``
        Faces (polygons are fan-triangulated for drawing; edges drawn are the polygon edges).
    scalars : (n,) or (m,) float array, optional
        One value per vertex (blended across faces) or per face (constant on each face), drawn
        with ``cmap`` and a colour bar.
    title : str
        Shown on the page and as its title.
    cmap : str
        A matplotlib colour map name.
    clim : (float, float), optional
        Colour range (default: the scalars' min and max).
    edges : bool, optional
        Draw the edges at first (default: when there are fewer than 20 000 of them).
    up : {"y", "z"}
        The mesh's up axis (kept up while turning).
    scalar_name : str
        What the scalars are (shown next to the colour bar).

    Returns
    -------
    str
        HTML that loads nothing from the network.
    """
    where = "html_page"
    if up not in ("y", "z"):
        raise MeshError(f"{where}: up must be 'y' or 'z', got {up!r}")
    V, T, E, s = _prepare(V, faces, scalars, where)
    data = {
        "positions": _b64(V, np.float32),
        "triangles": _b64(T, np.uint32),
        "edges": _b64(E, np.uint32),
        "up": 1 if up == "y" else 2,
        "edgesOn": bool(len(E) < 20000) if edges is None else bool(edges),
        "colors": None,
    }
    bar = ""
    if s is not None:
        rgb, ramp, lo, hi = _colors(s, cmap, clim)
        data["colors"] = _b64(rgb, np.uint8)
        stops = ", ".join(f"rgb({r},{g},{b})" for r, g, b in ramp[::-1])
        name = _html.escape(scalar_name)
        bar = (
            f'<div id="bar" style="background: linear-gradient({stops});"></div>'
            f'<div class="tick" style="top: 6px;">{_tick(hi, lo, hi)}</div>'
            f'<div class="tick" style="top: calc(12px + 45% - 8px);">{_tick(lo, lo, hi)}</div>'
            + (f'<div class="tick" style="top: calc(12px + 22% - 8px);">{name}</div>' if name else "")
        )
    info = f"{len(V):,} vertices, {len(T):,} triangles"
    page = _PAGE.replace("__TITLE__", _html.escape(title)).replace("__INFO__", _html.escape(info))
    return page.replace("__BAR__", bar).replace("__DATA__", json.dumps(data))


def write_html(path, V, faces, scalars=None, **options) -> Path:
    """Write :func:`html_page` to ``path`` (folders created); return the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(html_page(V, faces, scalars, **options), encoding="utf-8")
    return path


class NotebookView:
    """A notebook widget: the viewer page in an ``<iframe>`` (displayed by Jupyter, turned with the mouse)."""

    def __init__(self, page: str, height: int = 480):
        self.page = page
        self.height = height

    def _repr_html_(self) -> str:
        return (
            f'<iframe srcdoc="{_html.escape(self.page, quote=True)}" style="width: 100%; height: {self.height}px; '
            'border: 1px solid #ddd;" sandbox="allow-scripts"></iframe>'
        )


# --------------------------------------------------------------------------------------------
# Public entry points
# --------------------------------------------------------------------------------------------


def _pyvista_window(V, T, E, s, title, cmap, clim, edges):
    import pyvista as pv

    cells = np.hstack([np.full((len(T), 1), 3), T]).ravel()
    mesh = pv.PolyData(V, cells)
    pl = pv.Plotter(title=title)
    kw = {"show_edges": bool(edges if edges is not None else len(E) < 20000)}
    if s is not None:
        mesh.point_data["scalars"] = s
        kw.update(scalars="scalars", cmap=cmap, clim=clim)
    pl.add_mesh(mesh, **kw)
    pl.show()


def view(
    V,
    F,
    scalars=None,
    *,
    html=None,
    title: str = "mesh",
    cmap: str = "viridis",
    clim=None,
    edges: bool | None = None,
    up: str = "y",
    scalar_name: str = "",
):
    """Look at a mesh in 3D, the way the place allows.

    Parameters
    ----------
    V : (n, 3) float array
        Vertex positions.
    F : (m, k) int array, list of polygons, or ``(indices, offsets)``
        Faces.
    scalars : (n,) or (m,) float array, optional
        Per-vertex or per-face values drawn with a colour map and a colour bar.
    html : str or Path, optional
        Write the self-contained interactive page there instead of opening anything.
    title, cmap, clim, edges, up, scalar_name
        As in :func:`html_page`.

    Returns
    -------
    Path, NotebookView or None
        The page written (with ``html``); in a notebook a widget that displays itself; None after
        a pyvista window closes.

    Raises
    ------
    MeshError
        Bad arrays, or no way to show anything (no display, not in a notebook, no ``html``): the
        message says to pass ``html=``.
    """
    opts = dict(title=title, cmap=cmap, clim=clim, edges=edges, up=up, scalar_name=scalar_name)
    if html is not None:
        return write_html(html, V, F, scalars, **opts)
    if in_notebook():
        return NotebookView(html_page(V, F, scalars, **opts))
    if not has_display():
        raise MeshError(
            "view: no display here (DISPLAY/WAYLAND_DISPLAY unset) and not in a notebook; "
            "write an interactive page instead: view(V, F, html='mesh.html') or `geomlib view FILE --html mesh.html`"
        )
    Vp, T, E, s = _prepare(V, F, scalars, "view")
    if s is not None and clim is None:
        clim = (float(s.min()), float(s.max()))
    _pyvista_window(Vp, T, E, s, title, cmap, clim, edges)
    return None


def view_file(path, *, html=None, up: str = "y", scalars=None, edges: bool | None = None):
    """:func:`view` of the mesh in an OBJ, OFF or PLY file (title: the file name)."""
    from geomlib import mesh_io as io

    V, faces = io.read_mesh(path)
    return view(V, faces, scalars, html=html, title=Path(path).name, up=up, edges=edges)
