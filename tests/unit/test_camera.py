"""Camera matrices: hand-computed values and the defining properties of each OpenGL convention."""

import doctest

import numpy as np
import pytest

from geomlib import camera
from geomlib.camera import (
    PRESETS,
    VIEWS,
    camera_presets,
    look_at,
    orthographic,
    perspective,
    pose_from_view,
    project,
    view_frame,
    viewport,
)
from geomlib.validate import MeshError


def hom(p):
    return np.append(np.asarray(p, float), 1.0)


def to_ndc(M, p):
    c = M @ hom(p)
    return c[:3] / c[3]


# ---------------------------------------------------------------------------------------------- look_at


def test_look_at_down_minus_z_is_a_translation():
    # Camera at (0, 0, 5) looking at the origin, up = y: eye space is world space shifted by -5 in z.
    expected = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, -5], [0, 0, 0, 1.0]])
    np.testing.assert_allclose(look_at((0, 0, 5), (0, 0, 0)), expected, atol=1e-15)


def test_look_at_from_plus_x_by_hand():
    # f = (-1, 0, 0), s = f x up = (0, 0, -1), u = s x f = (0, 1, 0); rows s, u, -f; t = -R eye.
    expected = np.array([[0, 0, -1, 0], [0, 1, 0, 0], [1, 0, 0, -1], [0, 0, 0, 1.0]])
    np.testing.assert_allclose(look_at((1, 0, 0), (0, 0, 0)), expected, atol=1e-15)


@pytest.mark.parametrize(
    "eye,target,up",
    [
        ((3, 2, 1), (0.5, -1, 2), (0, 1, 0)),
        ((-4, 0.3, 7), (1, 1, 1), (0.2, 1, -0.1)),
        ((0, 10, 0.01), (0, 0, 0), (0, 0, -1)),
    ],
)
def test_look_at_properties(eye, target, up):
    V = look_at(eye, target, up)
    R = V[:3, :3]
    np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-12)  # rigid
    assert np.linalg.det(R) == pytest.approx(1.0)  # right-handed stays right-handed
    np.testing.assert_allclose(V @ hom(eye), [0, 0, 0, 1], atol=1e-12)  # eye -> origin
    dist = np.linalg.norm(np.subtract(target, eye))
    np.testing.assert_allclose(V @ hom(target), [0, 0, -dist, 1], atol=1e-12)  # target on the -z axis
    u = R @ np.asarray(up, float)
    assert abs(u[0]) < 1e-12 and u[1] > 0  # up lands in the upper half of the yz plane
    np.testing.assert_array_equal(V[3], [0, 0, 0, 1])


def test_look_at_errors():
    with pytest.raises(MeshError, match="coincide"):
        look_at((1, 2, 3), (1, 2, 3))
    with pytest.raises(MeshError, match="parallel"):
        look_at((0, 5, 0), (0, 0, 0), up=(0, 1, 0))
    with pytest.raises(MeshError, match="zero"):
        look_at((0, 0, 5), (0, 0, 0), up=(0, 0, 0))
    with pytest.raises(MeshError, match="eye"):
        look_at((0, 0), (0, 0, 0))
    with pytest.raises(MeshError, match="target"):
        look_at((0, 0, 1), (0, np.nan, 0))


# ---------------------------------------------------------------------------------------------- projections


def test_perspective_by_hand():
    # fov 90 -> f = 1; aspect 2; near 1, far 3: (f+n)/(n-f) = -2, 2fn/(n-f) = -3.
    expected = np.array([[0.5, 0, 0, 0], [0, 1, 0, 0], [0, 0, -2, -3], [0, 0, -1, 0.0]])
    np.testing.assert_allclose(perspective(90, 2.0, 1.0, 3.0), expected, atol=1e-15)


@pytest.mark.parametrize("fov,aspect,near,far", [(60, 1.0, 0.1, 100.0), (35, 1.6, 2.0, 7.5), (120, 0.5, 0.01, 1.0)])
def test_perspective_properties(fov, aspect, near, far):
    P = perspective(fov, aspect, near, far)
    assert to_ndc(P, (0.3, -0.2, -near))[2] == pytest.approx(-1.0)
    assert to_ndc(P, (5.0, 1.0, -far))[2] == pytest.approx(1.0)
    for z in (near, far, 0.5 * (near + far)):
        h = z * np.tan(np.radians(fov) / 2)
        np.testing.assert_allclose(to_ndc(P, (aspect * h, h, -z))[:2], [1, 1])  # frustum corner
        np.testing.assert_allclose(to_ndc(P, (-aspect * h, -h, -z))[:2], [-1, -1])
    assert (P @ hom((1, 2, -3)))[3] == pytest.approx(3.0)  # clip w = -z_eye
    zs = -np.linspace(near, far, 20)
    z_ndc = [to_ndc(P, (0, 0, z))[2] for z in zs]
    assert np.all(np.diff(z_ndc) > 0)  # farther = larger depth


def test_orthographic_by_hand_and_corners():
    l, r, b, t, n, f = -1.0, 3.0, -2.0, 2.0, 1.0, 5.0
    expected = np.array([[0.5, 0, 0, -0.5], [0, 0.5, 0, 0], [0, 0, -0.5, -1.5], [0, 0, 0, 1.0]])
    P = orthographic(l, r, b, t, n, f)
    np.testing.assert_allclose(P, expected, atol=1e-15)
    np.testing.assert_allclose(to_ndc(P, (l, b, -n)), [-1, -1, -1])
    np.testing.assert_allclose(to_ndc(P, (r, t, -f)), [1, 1, 1])


def test_projection_errors():
    for args in [
        (0, 1, 0.1, 10),
        (180, 1, 0.1, 10),
        (60, 0, 0.1, 10),
        (60, 1, 0, 10),
        (60, 1, 2, 1),
        (60, 1, np.nan, 1),
    ]:
        with pytest.raises(MeshError, match="perspective"):
            perspective(*args)
    with pytest.raises(MeshError, match="left and right"):
        orthographic(1, 1, 0, 1, 0, 1)
    with pytest.raises(MeshError, match="near and far"):
        orthographic(0, 1, 0, 1, 2, 2)


# ---------------------------------------------------------------------------------------------- viewport, project


def test_viewport_by_hand():
    W = viewport(4, 2)
    expected = np.array([[2, 0, 0, 2], [0, 1, 0, 1], [0, 0, 0.5, 0.5], [0, 0, 0, 1.0]])
    np.testing.assert_allclose(W, expected)
    np.testing.assert_allclose(W @ [-1, -1, -1, 1], [0, 0, 0, 1])  # bottom-left, near
    np.testing.assert_allclose(W @ [1, 1, 1, 1], [4, 2, 1, 1])  # top-right, far
    with pytest.raises(MeshError, match="width"):
        viewport(0, 3)


def test_project_pixel_centres_and_row_zero_on_top():
    width, height = 8, 4
    M = np.eye(4)  # clip = world: NDC is the input
    # The centre of pixel (row r, col c) is at x_win = c + 0.5, y_win = height - r - 0.5.
    r, c = 1, 6
    ndc = np.array([[2 * (c + 0.5) / width - 1, 2 * (height - r - 0.5) / height - 1, 0.0]])
    xy, depth = project(ndc, M, width, height)
    np.testing.assert_allclose(xy, [[c + 0.5, r + 0.5]])
    np.testing.assert_allclose(depth, [0.5])
    xy, _ = project(np.array([[-1, 1, 0.0], [1, -1, 0.0]]), M, width, height)  # NDC top-left, bottom-right
    np.testing.assert_allclose(xy, [[0, 0], [width, height]])


def test_project_matches_viewport_and_handles_points_behind():
    M = perspective(50, 1.5, 0.5, 20) @ look_at((1, 2, 6), (0, 0, 0))
    X = np.array([[0.1, 0.2, 0.3], [-1, 0.5, 2], [1, 2, 7.0]])  # the last one is behind the camera
    xy, depth = project(X, M, 60, 40)
    for i in range(2):
        win = viewport(60, 40) @ np.append(to_ndc(M, X[i]), 1)
        np.testing.assert_allclose(xy[i], [win[0], 40 - win[1]])
        assert depth[i] == pytest.approx(win[2])
    assert np.isnan(xy[2]).all() and np.isnan(depth[2])
    with pytest.raises(MeshError, match="P has shape"):
        project(np.zeros((3, 2)), M, 60, 40)


# ---------------------------------------------------------------------------------------------- presets


@pytest.mark.parametrize("name", PRESETS)
def test_camera_presets_frame_the_box(name):
    bounds = np.array([[-1.0, 0.0, -0.5], [3.0, 1.0, 0.5]])
    eye, target, up = camera_presets(name, bounds, fov_y_deg=40)
    np.testing.assert_allclose(target, bounds.mean(0))
    M = perspective(40, 1.0, 0.1, 100) @ look_at(eye, target, up)
    corners = np.array([[x, y, z] for x in bounds[:, 0] for y in bounds[:, 1] for z in bounds[:, 2]])
    xy, _ = project(corners, M, 100, 100)
    assert np.all((xy > 0) & (xy < 100)), xy


def test_camera_presets_directions():
    bounds = np.array([[-1.0, -1, -1], [1, 1, 1]])
    eye, _, up = camera_presets("front", bounds)
    assert eye[2] > 0 and eye[0] == eye[1] == 0 and tuple(up) == (0, 1, 0)
    eye, _, up = camera_presets("top", bounds)
    assert eye[1] > 0 and eye[0] == eye[2] == 0
    V = look_at(eye, (0, 0, 0), up)
    assert (V[:3, :3] @ [1, 0, 0])[0] == pytest.approx(1)  # +x stays to the right in the top view
    eye, _, _ = camera_presets("three_quarter", bounds)  # azimuth 35 degrees towards +x, elevation 25
    d = eye / np.linalg.norm(eye)
    assert np.degrees(np.arctan2(d[0], d[2])) == pytest.approx(35) and np.degrees(np.arcsin(d[1])) == pytest.approx(25)


def test_camera_presets_errors():
    with pytest.raises(MeshError, match="name must be one of"):
        camera_presets("sideways", np.zeros((2, 3)))
    with pytest.raises(MeshError, match="min corner"):
        camera_presets("front", [[1, 1, 1], [0, 0, 0]])
    with pytest.raises(MeshError, match="bounds has shape"):
        camera_presets("front", np.zeros((5, 3)))


def test_docstring_examples():
    assert doctest.testmod(camera, raise_on_error=False).failed == 0


# ------------------------------------------------------------------------------ one preset table


@pytest.mark.parametrize("view", sorted(VIEWS))
@pytest.mark.parametrize("up_axis", ["y", "z"])
def test_rasterizer_and_renderer_share_the_view_table(view, up_axis):
    """camera_presets (rasterizer labs) and render.camera_pose (figures) look from the same direction."""
    from geomlib.render import camera_pose

    bounds = np.array([[-1.0, -0.5, -0.2], [1.0, 0.5, 0.2]])
    eye, target, up = camera_presets(view, bounds, up_axis=up_axis)
    pose = camera_pose(bounds, view, up_axis=up_axis)
    back = (eye - target) / np.linalg.norm(eye - target)
    np.testing.assert_allclose(pose[:3, 2], back, atol=1e-12)  # the pose's +z points back at the viewer
    # same image up, and the view matrix of the same camera is the inverse of the pose (one convention)
    np.testing.assert_allclose(pose_from_view(look_at(eye, target, up))[:3, :3], pose[:3, :3], atol=1e-12)


def test_view_frame_angles_and_forward():
    az, el = VIEWS["three_quarter"]
    back, up = view_frame("three_quarter", "y")
    assert np.degrees(np.arctan2(back[0], back[2])) == pytest.approx(az)
    assert np.degrees(np.arcsin(back[1])) == pytest.approx(el) and tuple(up) == (0, 1, 0)
    # z up: the datasets face -y, so the front camera stands on -y; the top view has +y up in the image
    assert tuple(view_frame("front", "z")[0]) == (0, -1, 0)
    assert tuple(view_frame("top", "z")[0]) == (0, 0, 1) and tuple(view_frame("top", "z")[1]) == (0, 1, 0)
    # a model that faces -z (spot): the front and three-quarter views stand on its -z side
    assert tuple(view_frame("front", "y", "-z")[0]) == (0, 0, -1)
    assert view_frame("three_quarter", "y", "-z")[0][2] < 0
    assert tuple(view_frame("back", "y")[0]) == (0, 0, -1) and tuple(view_frame("right", "y")[0]) == (1, 0, 0)
    with pytest.raises(MeshError, match="perpendicular"):
        view_frame("front", "y", "-y")
    with pytest.raises(MeshError, match="view must be one of"):
        view_frame("diagonal")


def test_pose_from_view_inverts_look_at():
    V = look_at((1.0, 2.0, 3.0), (0.5, -1.0, 0.0), (0, 0, 1))
    np.testing.assert_allclose(pose_from_view(V) @ V, np.eye(4), atol=1e-12)


def test_perspective_look_at_is_the_product():
    eye, target, up = (1.0, -2.0, 1.5), (0.2, 0.1, 0.0), (0, 0, 1)
    M = camera.perspective_look_at(eye, target, up, 35, 1.5, 0.2, 9.0)
    np.testing.assert_array_equal(M, camera.perspective(35, 1.5, 0.2, 9.0) @ camera.look_at(eye, target, up))
    with pytest.raises(MeshError, match="near < far"):
        camera.perspective_look_at(eye, target, up, 35, 1.5, 2.0, 1.0)
