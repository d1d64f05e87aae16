"""Hidden graded cases (not shipped to students): the same tasks on other inputs, and the GLSL route."""

from geomlib.grading import graded, reference_tests

from .cases_hidden import CASES as HIDDEN_CASES
from .test_denoise import check_glsl_denoise

test_hidden_references = reference_tests(HIDDEN_CASES)


@graded(points=4, part="vertex denoising", visibility="hidden", timeout=60)
def test_glsl_denoise_with_map_hidden(lab):
    """shaders/denoise.vert on a hidden map (a grid, 16 bits, repeat wrap)"""
    check_glsl_denoise(lab, "hidden-map-uv-grid-repeat")
