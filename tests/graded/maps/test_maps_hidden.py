"""Hidden graded tests of the lab "maps": hidden references and the GLSL route on hidden inputs."""

from geomlib.grading import graded, reference_tests

from .cases_hidden import CASES as HIDDEN_CASES
from .test_maps import check_glsl_displace, check_glsl_shade, check_glsl_tbn, rotation_model

test_hidden_references = reference_tests(HIDDEN_CASES)


@graded(points=4, part="vertex TBN", visibility="hidden", timeout=60)
def test_glsl_tbn_hidden(lab):
    """shaders/tbn.vert on hidden meshes (an atlas with mirrored charts, given normals), rotated"""
    check_glsl_tbn(lab, "tangents-rock-atlas")
    check_glsl_tbn(lab, "tangents-torus-given-normals", rotation_model())


@graded(points=4, part="fragment normal mapping", visibility="hidden", timeout=60)
def test_glsl_shade_hidden(lab):
    """shaders/normalmap.frag on a hidden case (albedo texture, two lights)"""
    check_glsl_shade(lab, "shade-torus-texture")


@graded(points=3, part="vertex displacement", visibility="hidden", timeout=60)
def test_glsl_displace_hidden(lab):
    """shaders/displace.vert on a hidden case (repeat wrap)"""
    check_glsl_displace(lab, "displace-sphere-bias0-scale1-repeat")
