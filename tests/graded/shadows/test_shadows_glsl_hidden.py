"""Hidden graded tests of the shadows lab's GLSL route (tasks 9-10): other lights, maps and options."""

from geomlib.grading import graded

from .test_shadows_glsl import check_glsl_cube_face, check_glsl_depth, check_glsl_shadow


@graded(points=4, part="light pass", visibility="hidden", timeout=120)
def test_glsl_depth_map_hidden(lab):
    """shaders/depth.vert + depth.frag on a hidden light, and the six front-culled faces of a point light"""
    check_glsl_depth(lab, "hidden-depth-80")
    for face in range(6):
        check_glsl_cube_face(lab, "hidden-", 48, face)


@graded(points=2, part="fragment shadow test", visibility="hidden", timeout=60)
def test_glsl_shadow_pcf_hidden(lab):
    """shaders/shadow.frag: 5 x 5 PCF with a large slope factor (a map over part of the view), and 32 Poisson
    samples on a hidden spot light"""
    check_glsl_shadow(lab, "hidden-glsl-eye-m2-pcf5")
    check_glsl_shadow(lab, "hidden-glsl-eye-s2-poisson32")


@graded(points=2, part="fragment shadow test", visibility="hidden", timeout=60)
def test_glsl_shadow_bias_hidden(lab):
    """the default bias on a hidden light, and a small max_slope clamp (a spot whose far plane cuts the floor)"""
    check_glsl_shadow(lab, "hidden-glsl-eye-m2-defaults")
    check_glsl_shadow(lab, "hidden-glsl-eye-s2-max-slope")


@graded(points=2, part="fragment shadow test", visibility="hidden", timeout=60)
def test_glsl_shadow_frustum_hidden(lab):
    """a map that covers part of the view: beside it lit with the fix, border texels without"""
    check_glsl_shadow(lab, "hidden-glsl-eye-partial")
    check_glsl_shadow(lab, "hidden-glsl-eye-partial-nofix")
