"""Tests for geomlib.render: headless pyrender images, cameras, validation.

OSMesa renders are slow (about a second cold), so the six renders below are shared through
module-scoped fixtures; everything else (cameras, validation, import hygiene) needs no OpenGL.
Expected values come from the geometry of the scene (a sphere framed by the camera covers
about pi/4 of the image height squared, a floor under a box is darker where shadowed).
"""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

from geomlib import render as R
from geomlib.render import shading
from geomlib.validate import MeshError

SIZE = (160, 120)  # small: OSMesa time grows with pixels (supersampled x2)
WHITE = np.array([255, 255, 255])


def uv_sphere(n_lat: int = 12, n_lon: int = 24) -> tuple[np.ndarray, np.ndarray]:
    """Closed unit sphere, outward-facing triangles (built here so the test needs no other module)."""
    th = np.linspace(0, np.pi, n_lat + 1)[1:-1]
    ph = np.linspace(0, 2 * np.pi, n_lon, endpoint=False)
    T, P = np.meshgrid(th, ph, indexing="ij")
    V = np.vstack(
        [[0, 0, 1], np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], -1).reshape(-1, 3), [0, 0, -1]]
    )
    ring = lambda i, j: 1 + i * n_lon + (j % n_lon)  # noqa: E731
    F = [[0, ring(0, j), ring(0, j + 1)] for j in range(n_lon)]
    for i in range(n_lat - 2):
        for j in range(n_lon):
            a, b, c, d = ring(i, j), ring(i + 1, j), ring(i + 1, j + 1), ring(i, j + 1)
            F += [[a, b, c], [a, c, d]]
    s = len(V) - 1
    F += [[s, ring(n_lat - 2, j + 1), ring(n_lat - 2, j)] for j in range(n_lon)]
    return V, np.array(F)


def mesh_mask(img: np.ndarray) -> np.ndarray:
    """Pixels that are not the white background."""
    return np.any(img != WHITE, axis=2)


@pytest.fixture(scope="module")
def sphere():
    return uv_sphere()


@pytest.fixture(scope="module")
def plain(sphere):
    V, F = sphere
    return R.render(V, F, size=SIZE), R.render(V, F, size=SIZE)


@pytest.fixture(scope="module")
def wired(sphere):
    V, F = sphere
    # Vertex 0 is the north pole; the three_quarter view (z up) looks at it from above.
    return R.render(V, F, size=SIZE, wireframe=True, highlight_points=[0], point_radius=3)


@pytest.mark.render
def test_render_shape_and_not_blank(plain):
    img = plain[0]
    assert img.shape == (SIZE[1], SIZE[0], 3) and img.dtype == np.uint8
    assert len(np.unique(img.reshape(-1, 3), axis=0)) > 20, "the render is (nearly) a single colour"
    # The preset frames the sphere to ~94% of the image height: a disk of area pi/4 * (0.94 h)^2.
    frac = mesh_mask(img).mean()
    expected = np.pi / 4 * (0.94 * SIZE[1]) ** 2 / (SIZE[0] * SIZE[1])
    assert abs(frac - expected) < 0.08, f"sphere covers {frac:.2f} of the image, expected about {expected:.2f}"
    # Shaded, not flat: the lit sphere has a range of brightness.
    lum = img[mesh_mask(img)].mean(axis=1)
    assert lum.max() - lum.min() > 60


@pytest.mark.render
def test_render_is_deterministic(plain):
    a, b = plain
    assert np.abs(a.astype(int) - b.astype(int)).max() <= 1


@pytest.mark.render
def test_wireframe_adds_dark_pixels_and_points(plain, wired):
    dark = lambda im: (im.mean(axis=2) < 90).sum()  # noqa: E731
    n_mesh = mesh_mask(plain[0]).sum()
    assert dark(wired) > dark(plain[0]) + 0.03 * n_mesh, "wireframe should draw dark lines over the mesh"
    # Same silhouette: the overlay draws on the mesh, it does not move it.
    assert (mesh_mask(wired) != mesh_mask(plain[0])).mean() < 0.02
    red = lambda im: ((im[..., 0] > 180) & (im[..., 1] < 90) & (im[..., 2] < 90)).sum()  # noqa: E731
    assert red(plain[0]) == 0 and red(wired) >= 5, "the highlighted vertex should show as a red dot"


@pytest.mark.render
def test_vertex_colors_show(sphere):
    V, F = sphere
    img = R.render(V, F, size=SIZE, colors=np.tile([1.0, 0.0, 0.0], (len(V), 1)))
    px = img[mesh_mask(img)].astype(float)
    assert px[:, 0].mean() > 2 * px[:, 1].mean() and px[:, 0].mean() > 2 * px[:, 2].mean()
    assert (px[:, 0] > 120).mean() > 0.5, "most of the sphere should be clearly red"


@pytest.mark.render
def test_shadows_darken_the_floor():
    # A floor quad at z = 0 and a box floating above it, as one polygon mesh; light slanting down.
    floor = np.array([[-2, -2, 0], [2, -2, 0], [2, 2, 0], [-2, 2, 0.0]])
    cube = np.array([[x, y, z] for z in (1.0, 1.5) for y in (-0.5, 0.5) for x in (-0.5, 0.5)])
    V = np.vstack([floor, cube])
    c = lambda *i: [4 + k for k in i]  # noqa: E731
    faces = [[0, 1, 2, 3], c(0, 2, 3, 1), c(4, 5, 7, 6), c(0, 1, 5, 4), c(2, 6, 7, 3), c(0, 4, 6, 2), c(1, 3, 7, 5)]
    light = [{"type": "directional", "direction": (0.35, 0.25, -1.0), "intensity": 3.0}]
    kw = dict(size=SIZE, camera="top", light=light, ambient=0.3)
    off = R.render_polygons(V, faces, shadows=False, **kw).astype(float)
    on = R.render_polygons(V, faces, shadows=True, **kw).astype(float)
    darker = (off.mean(axis=2) - on.mean(axis=2)) > 40
    # The box's shadow is offset by about (0.35, 0.25) * height ~ 0.4 units: a visible band on the floor.
    assert darker.mean() > 0.02, f"only {darker.mean():.3f} of the pixels got darker with shadows"
    assert on.mean() < off.mean()


# -- no OpenGL needed below ---------------------------------------------------------------------


def project(V, pose, fov_deg, size):
    """Normalised device coordinates of points seen by a camera-to-world pose (independent of render.py)."""
    W2C = np.linalg.inv(pose)
    X = V @ W2C[:3, :3].T + W2C[:3, 3]
    ty = np.tan(np.radians(fov_deg) / 2)
    z = -X[:, 2]
    return X[:, 0] / (z * ty * size[0] / size[1]), X[:, 1] / (z * ty), z


@pytest.mark.parametrize("view", R.VIEWS)
def test_camera_presets_frame_the_mesh(sphere, view):
    V, _ = sphere
    V = V * [2.0, 1.0, 0.5] + [10.0, -3.0, 1.0]  # an off-centre ellipsoid
    pose = R.camera_pose(V, view, fov_deg=35, size=(640, 480), margin=0.06)
    assert np.allclose(pose, R.camera_pose(V, view, fov_deg=35, size=(640, 480), margin=0.06))
    assert np.allclose(pose[:3, :3].T @ pose[:3, :3], np.eye(3))
    x, y, z = project(V, pose, 35, (640, 480))
    assert (z > 0).all()
    extent = max(np.abs(x).max(), np.abs(y).max())
    assert extent <= 0.94 + 1e-6, "every vertex lies inside the frame, margin kept"
    assert extent > 0.90, "the object fills the frame (tight fit along one axis)"
    assert abs(x.max() + x.min()) < 0.05 and abs(y.max() + y.min()) < 0.05, "the object is centred"


def test_camera_top_looks_down_z(sphere):
    pose = R.camera_pose(sphere[0], "top")
    assert np.allclose(pose[:3, 2], [0, 0, 1])  # camera +z axis points back at the viewer: looks down -z
    pose_y = R.camera_pose(sphere[0], "front", up_axis="y")
    assert np.allclose(pose_y[:3, 2], [0, 0, 1]) and np.allclose(pose_y[:3, 1], [0, 1, 0])


def test_backend_and_lazy_import():
    assert R.backend() == os.environ["PYOPENGL_PLATFORM"]
    code = (
        "import sys, geomlib.render, geomlib.plot, geomlib.gallery; "
        "print(any(m.split('.')[0] in ('pyrender', 'OpenGL') for m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False", "importing geomlib must not import pyrender or OpenGL"


def test_backend_respects_user_choice(monkeypatch):
    monkeypatch.setenv("PYOPENGL_PLATFORM", "egl")
    assert R.backend() == "egl"


def _backend_in_fresh_process(found: dict[str, bool]) -> subprocess.CompletedProcess:
    """Run backend() in a new interpreter (PyOpenGL not imported yet) with find_library faked."""
    code = (
        "import ctypes.util, sys\n"
        f"found = {found!r}\n"
        "ctypes.util.find_library = lambda name: ('lib' + name) if found.get(name) else None\n"
        "from geomlib import render\n"
        "try:\n"
        "    print(render.backend())\n"
        "except RuntimeError as e:\n"
        "    print('error:', e)\n"
    )
    env = {k: v for k, v in os.environ.items() if k != "PYOPENGL_PLATFORM"}
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True)


def test_backend_falls_back_to_egl_without_osmesa_and_names_the_fix_without_either():
    assert _backend_in_fresh_process({"OSMesa": True, "EGL": True}).stdout.strip() == "osmesa"
    assert _backend_in_fresh_process({"OSMesa": False, "EGL": True}).stdout.strip() == "egl"
    out = _backend_in_fresh_process({}).stdout
    assert "no headless OpenGL library found" in out and "apt-get install libosmesa6" in out


_EGL_RENDER = """
import sys
import numpy as np
from geomlib import datasets, render
V, F = datasets.icosphere(2)
img = render.render(V, F, size=(96, 72))
assert render.backend() == "egl"
np.save(sys.argv[1], img)
"""


def test_egl_fallback_renders_like_osmesa(tmp_path):
    """The EGL path really renders (Mesa EGL is installed here next to OSMesa) and agrees with OSMesa."""
    import ctypes.util

    if not ctypes.util.find_library("EGL"):
        pytest.skip("no libEGL on this machine: the EGL fallback cannot be exercised")
    out = tmp_path / "egl.npy"
    env = dict(os.environ, PYOPENGL_PLATFORM="egl")
    run = subprocess.run(
        [sys.executable, "-c", _EGL_RENDER, str(out)], capture_output=True, text=True, env=env, timeout=300
    )
    if run.returncode != 0 and "EGL" in run.stderr and not out.exists():
        pytest.skip(f"libEGL is present but has no usable device here: {run.stderr.strip().splitlines()[-1]}")
    assert run.returncode == 0, run.stderr
    egl = np.load(out)
    from geomlib import datasets

    V, F = datasets.icosphere(2)
    ref = R.render(V, F, size=(96, 72))  # this process's platform (OSMesa when present)
    assert egl.shape == ref.shape == (72, 96, 3)
    diff = np.abs(egl.astype(int) - ref.astype(int))
    assert (egl != 255).any(axis=2).mean() > 0.2, "the EGL image is empty"
    assert diff.mean() < 2.0 and (diff > 16).mean() < 0.01, f"EGL and {R.backend()} renders differ: {diff.mean():.2f}"


@pytest.mark.parametrize(
    ("change", "match"),
    [
        (dict(V=np.zeros((4, 2))), r"render: V has shape \(4, 2\), expected \(n, 3\)"),
        (dict(V="nan"), r"render: V: row 2 has a non-finite value"),
        (dict(F=[[0, 1, 9]]), r"face 0 uses vertex 9, but V has only 4 vertices"),
        (dict(colors=np.ones((3, 3))), r"colors has 3 rows, expected 4 \(one colour per vertex\)"),
        (dict(colors=np.ones((4, 2))), r"colors has shape \(4, 2\)"),
        (dict(colors=np.full((4, 3), 1.5)), r"float colours must lie in \[0, 1\]"),
        (dict(face_colors=np.ones((3, 3))), r"face_colors has 3 rows, expected 4 \(one colour per face\)"),
        (dict(uv=np.zeros((4, 2))), r"uv and texture go together"),
        (dict(uv=np.zeros((3, 2)), texture=np.zeros((8, 8, 3))), r"uv has 3 rows, expected 4"),
        (dict(normals=np.zeros((4, 3))), r"normals: row 0 is the zero vector"),
        (dict(highlight_points=[7]), r"highlight_points has vertex index 7"),
        (
            dict(highlight_points=[0, 1], point_color=np.ones((3, 3))),
            r"point_color has 3 rows, expected 2 \(one colour per entry of highlight_points\)",
        ),
        (dict(point_color=np.ones((2, 3))), r"point_color gives one colour per dot, but highlight_points is not given"),
        (dict(highlight_lines=np.zeros((2, 3))), r"highlight_lines has shape \(2, 3\), expected \(n, 2, 3\)"),
        (dict(highlight_lines=np.zeros((1, 2, 3)), line_width=0), r"line_width must be > 0"),
        (dict(camera="isometric"), r"camera must be one of"),
        (dict(camera=np.eye(4) * 2), r"rigid camera-to-world"),
        (dict(size=(0, 10)), r"size\[0\] \(width\) must be >= 1"),
        (dict(fov_deg=float("nan")), r"fov_deg must be finite"),
        (dict(light="sun"), r"light must be one of"),
        (dict(light=[{"type": "spot"}]), r"light\[0\] is a spot light and needs a 'position'"),
        (dict(camera=((0, 0, 1), (0, 0, 1), (0, 1, 0))), r"render: camera eye .* coincide"),
        (dict(forward="+w"), r"forward must be one of"),
        (dict(colour=(1, 0, 0)), r"render: unknown option\(s\) \['colour'\]"),
    ],
)
def test_bad_input_raises_mesh_error(change, match):
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
    F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    args = dict(V=V, F=F) | change
    if isinstance(args["V"], str):
        args["V"] = np.where(np.arange(4)[:, None] == 2, np.nan, V)
    V_, F_ = args.pop("V"), args.pop("F")
    with pytest.raises(MeshError, match=match):
        R.render(V_, F_, **args)


@pytest.mark.render
def test_highlight_lines_are_drawn_where_visible(sphere, plain):
    V, F = sphere
    green = lambda img: int(((img[..., 1] > 120) & (img[..., 0] < 80) & (img[..., 2] < 120)).sum())  # noqa: E731
    # a segment over the top of the sphere (the three_quarter view sees it) and one under it (hidden)
    over = np.array([[[-0.7, 0.0, 1.01], [0.7, 0.0, 1.01]]])
    under = np.array([[[-0.2, 0.0, -1.01], [0.2, 0.0, -1.01]]])  # behind the sphere from every point of view above
    img = R.render(V, F, size=SIZE, highlight_lines=over, line_color=(0.0, 0.8, 0.1), line_width=3)
    hidden = R.render(V, F, size=SIZE, highlight_lines=under, line_color=(0.0, 0.8, 0.1), line_width=3)
    assert green(plain[0]) == 0 and green(img) >= 40, "a visible highlight line should be drawn in its colour"
    assert green(hidden) == 0, "a line behind the surface should be hidden by the depth test"


@pytest.mark.render
def test_highlight_points_take_one_colour_each(sphere, wired):
    """Dots coloured one by one (e.g. by valence): each visible dot in its own colour, one colour as before."""
    V, F = sphere
    red = lambda img: int(((img[..., 0] > 200) & (img[..., 1] < 60) & (img[..., 2] < 60)).sum())  # noqa: E731
    blue = lambda img: int(((img[..., 2] > 200) & (img[..., 0] < 60) & (img[..., 1] < 60)).sum())  # noqa: E731
    top = int(np.argmax(V[:, 2]))
    side = int(np.argmax(V @ [0.52, -0.74, 0.42]))  # facing the three_quarter eye (front right, above)
    kw = dict(size=SIZE, wireframe=True, highlight_points=[top, side], point_radius=3)
    both = R.render(V, F, point_color=[[0.9, 0.1, 0.1], [0.1, 0.1, 0.9]], **kw)
    assert red(both) >= 10 and blue(both) >= 10, "each dot should be drawn in its own colour"
    one = R.render(V, F, point_color=[[0.9, 0.1, 0.1], [0.9, 0.1, 0.1]], **kw)
    np.testing.assert_array_equal(one, R.render(V, F, point_color=(0.9, 0.1, 0.1), **kw))
    assert blue(one) == 0


@pytest.mark.render
def test_options_object_equals_keywords(sphere, wired):
    """One RenderOptions object and the same names as keywords draw the same image."""
    V, F = sphere
    opts = R.RenderOptions(size=SIZE, wireframe=True, highlight_points=[0], point_radius=3)
    np.testing.assert_array_equal(R.render(V, F, opts), wired)
    np.testing.assert_array_equal(R.render(V, F, opts.replace(wireframe=False), wireframe=True), wired)
    with pytest.raises(MeshError, match=r"unknown option\(s\) \['wire'\]"):
        opts.replace(wire=True)
    with pytest.raises(MeshError, match="options must be a RenderOptions"):
        R.render(V, F, {"size": SIZE})


def test_camera_pose_forward_axis(sphere):
    """A model that faces -z (spot) is seen from its -z side by the front and three-quarter views."""
    assert np.allclose(R.camera_pose(sphere[0], "front", up_axis="y", forward="-z")[:3, 2], [0, 0, -1])
    assert R.camera_pose(sphere[0], "three_quarter", up_axis="y", forward="-z")[2, 3] < 0


def test_render_polygons_bad_input():
    V = np.zeros((4, 3))
    with pytest.raises(MeshError, match=r"render_polygons: faces: face 1 has 2 vertices"):
        R.render_polygons(V, [[0, 1, 2], [2, 3]])
    with pytest.raises(MeshError, match=r"render_polygons: unknown option\(s\) \['colour'\]"):
        R.render_polygons(V, [[0, 1, 2, 3]], colour=(1, 0, 0))


def test_crease_normals_split_sharp_edges_only():
    # A cube: every face meets its neighbours at 90 degrees, so with a 60-degree crease angle each
    # corner's normal is its own face's axis-aligned normal.
    Vc = np.array([[x, y, z] for z in (0.0, 1.0) for y in (0.0, 1.0) for x in (0.0, 1.0)])
    quads = np.array([[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]])
    T = np.concatenate([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])
    tri_n = np.cross(Vc[T[:, 1]] - Vc[T[:, 0]], Vc[T[:, 2]] - Vc[T[:, 0]])
    vert_n = shading.vertex_normals(len(Vc), T, tri_n)
    corner = shading.crease_normals(T, tri_n, vert_n, 60.0)
    np.testing.assert_allclose(shading.unit(corner), np.repeat(shading.unit(tri_n), 3, axis=0), atol=1e-12)
    # Smooth sphere: neighbouring faces are ~10 degrees apart, nothing to split.
    V, F = uv_sphere(24, 48)
    tri_n = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    assert shading.crease_normals(F, tri_n, shading.vertex_normals(len(V), F, tri_n), 60.0) is None


def test_auto_wire_opacity_fades_with_screen_edge_length():
    from geomlib import datasets, topology
    from geomlib.render import auto_wire_opacity

    V, F = datasets.icosphere(0)
    assert auto_wire_opacity(V, topology.unique_edges(F), (640, 480)) == 1.0  # long edges: full wireframe
    V, F = datasets.icosphere(7)  # 327,680 faces: edges ~0.5 px at 320x240
    assert auto_wire_opacity(V, topology.unique_edges(F), (320, 240)) == 0.0
    V, F = datasets.icosphere(4)
    mid = auto_wire_opacity(V, topology.unique_edges(F), (320, 240))
    assert 0.0 < mid < 1.0


# A process that has rendered, then forks (the grader's feedback pictures, a notebook that grades
# after drawing figures): Mesa's rasteriser threads stay in the parent, so the child must not touch
# OpenGL. Run in a fresh interpreter so the parent has certainly rendered, whatever ran before.
_FORK_AFTER_RENDER = """
import os, pickle, sys
import numpy as np
from geomlib import render as R
from geomlib import gl
from geomlib.render import context
from geomlib.validate import MeshError

V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
parent = R.render(V, F, size=(48, 40))
r, w = os.pipe()
pid = os.fork()
if pid == 0:
    out = {"inherited": context.inherited_context()}
    out["same"] = bool(np.array_equal(R.render(V, F, size=(48, 40)), parent))
    out["polygons"] = R.render_polygons(V, [[0, 2, 1], [0, 1, 3, 2]], size=(48, 40)).shape
    for name, call in [("bad", lambda: R.render(V, F[:, :2])), ("direct", lambda: context.offscreen_renderer(8, 8)),
                       ("gl", lambda: gl.renderer_info())]:
        try:
            call()
            out[name] = "no error"
        except Exception as e:
            out[name] = (type(e).__name__, str(e))
    os.write(w, pickle.dumps(out))
    os._exit(0)
os.close(w)
data = b"".join(iter(lambda: os.read(r, 1 << 16), b""))
os.waitpid(pid, 0)
sys.stdout.buffer.write(data)
"""


@pytest.mark.render
def test_a_process_forked_after_rendering_renders_in_a_fresh_one():
    import pickle

    proc = subprocess.run([sys.executable, "-c", _FORK_AFTER_RENDER], capture_output=True, timeout=120)
    assert proc.returncode == 0, proc.stderr.decode()[-2000:]
    out = pickle.loads(proc.stdout)
    assert out["inherited"] is True
    assert out["same"], "the image drawn in the fresh process differs from the parent's"
    assert out["polygons"] == (40, 48, 3)
    assert out["bad"][0] == "MeshError" and "(m, 3)" in out["bad"][1]  # the entry point's own error, not a pipe's
    for name in ("direct", "gl"):  # raw GL in the child: a clear error instead of a hang
        assert out[name][0] == "RuntimeError" and "does not survive a fork" in out[name][1], out[name]


def test_dots_are_stamped_exactly_as_a_dilation_would_draw_them():
    """Highlighted points are stamped per dot (a dilation of the whole supersampled image took ~0.25 s
    per call, over a second per feedback picture); the pixels are the same, odd and even disks, at the
    border too."""
    from scipy import ndimage

    from geomlib.render.overlay import _disk, _stamped

    rng = np.random.default_rng(3)
    H, W = 90, 70
    for diameter in (1.0, 4.0, 7.7, 13.0, 20.0):
        iy, ix = rng.integers(0, H, 9), rng.integers(0, W, 9)
        iy[0], ix[0] = 0, W - 1  # a corner dot: the disk is cut by the frame
        dots = np.zeros((H, W), bool)
        dots[iy, ix] = True
        expected = ndimage.binary_dilation(dots, structure=_disk(diameter))
        assert np.array_equal(_stamped(iy, ix, _disk(diameter), (H, W)), expected), diameter
