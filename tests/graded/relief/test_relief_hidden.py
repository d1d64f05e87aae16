"""Hidden graded tests of the lab "relief": hidden references and the GLSL route on hidden inputs."""

from geomlib.grading import graded, reference_tests

from .cases_hidden import CASES as HIDDEN_CASES
from .test_relief import check_glsl_case

test_hidden_references = reference_tests(HIDDEN_CASES)


@graded(points=2, part="GLSL parallax", visibility="hidden", timeout=60)
def test_glsl_parallax_hidden(lab):
    """shaders/parallax.frag on hidden inputs"""
    check_glsl_case(lab, "parallax-random-views", "glsl_parallax_uv")
    check_glsl_case(lab, "parallax-limited-random-views", "glsl_parallax_uv")


@graded(points=3, part="GLSL relief mapping", visibility="hidden", timeout=60)
def test_glsl_relief_hidden(lab):
    """shaders/relief.frag on hidden inputs (linear, secant and binary refinement)"""
    check_glsl_case(lab, "relief-linear-bumps-40-layers-4-64", "glsl_relief_uv")
    check_glsl_case(lab, "relief-secant-steps-perspective", "glsl_relief_uv")
    check_glsl_case(lab, "relief-binary-steps-80", "glsl_relief_uv")


@graded(points=2, part="GLSL self-shadowing", visibility="hidden", timeout=60)
def test_glsl_shadow_hidden(lab):
    """shaders/shadow.frag on hidden inputs"""
    check_glsl_case(lab, "shadow-steps-60", "glsl_relief_shadow")
