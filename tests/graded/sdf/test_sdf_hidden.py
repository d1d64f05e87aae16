"""Hidden graded tests of the lab "sdf"."""

from geomlib.grading import graded, reference_tests

from .cases import KERNEL_TIMEOUT
from .cases_hidden import CASES as HIDDEN_CASES
from .support import box_mesh, wedge
from .test_sdf import _bvh_test

test_hidden_references = reference_tests(HIDDEN_CASES)


@graded(points=2, part="BVH", visibility="hidden", timeout=KERNEL_TIMEOUT)
def test_bvh_is_valid_box_leaf1(lab):
    """build_bvh on a box with one triangle per leaf"""
    _bvh_test(lab, box_mesh, 1)


@graded(points=1, part="BVH", visibility="hidden", timeout=KERNEL_TIMEOUT)
def test_bvh_is_valid_wedge_leaf3(lab):
    """build_bvh on an L-shaped prism with up to three triangles per leaf"""
    _bvh_test(lab, wedge, 3)
