"""Hidden graded cases (not shipped to students): the same rules on other meshes."""

from geomlib.grading import reference_tests

from .cases_hidden import CASES as HIDDEN_CASES

test_hidden_references = reference_tests(HIDDEN_CASES)
