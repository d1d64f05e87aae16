import numpy as np

from geomlib.grading import expect_close, expect_raises, graded, reference_tests

from .cases import CASES, TET_F, TET_V

test_references = reference_tests(CASES)


@graded(points=1, part="scaling")
def test_scale_by_one_is_identity(lab):
    """scaling by 1 changes nothing"""
    V = lab.scale_about_centroid(TET_V, TET_F, 1.0)
    expect_close("scale_about_centroid(s=1)", V, TET_V, atol=1e-12)


@graded(points=1, part="midpoints")
def test_one_triangle_midpoints(lab):
    """one triangle: three midpoints by hand"""
    V = np.array([[0.0, 0, 0], [2, 0, 0], [0, 2, 0]])
    E, M = lab.edge_midpoints(V, [[0, 1, 2]])
    expect_close("edge_midpoints on one triangle", M, [[1, 0, 0], [0, 1, 0], [1, 1, 0]], atol=1e-12)


@graded(points=0, part="bad input")
def test_rejects_nan(lab):
    """NaN coordinates are rejected with a message naming the row"""
    V = TET_V.copy()
    V[2, 1] = np.nan
    expect_raises(lambda: lab.scale_about_centroid(V, TET_F), "MeshError", match="row 2", label="scale_about_centroid")
