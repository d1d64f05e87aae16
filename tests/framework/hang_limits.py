"""Wall-clock limits of the grading tooling, raised for the suite's own runs (a pytest plugin).

A feedback picture is stopped after ``tolerances.PICTURE_TIME_S`` (20 s): a limit for a drawing that
hangs. A picture takes about 2 s on a quiet machine, but the suite runs on 2 shared cores beside
other CPU-bound processes, where one took more than 20 s, and a test that expects a picture then
failed for the machine's speed. The suite's runs allow :data:`PICTURE_S`, still a limit for hangs.

In-process tests use the fixture ``generous_pictures`` (tests/framework/conftest.py); a grading
subprocess loads this module with ``-p tests.framework.hang_limits`` (its ``pytest_configure``).
"""

from __future__ import annotations

from geomlib.grading import tolerances

#: Seconds one feedback picture may take in the suite's runs (x10 above a loaded machine's need).
PICTURE_S = 300.0


def pytest_configure(config) -> None:
    assert hasattr(tolerances, "PICTURE_TIME_S"), "geomlib.grading.tolerances lost PICTURE_TIME_S: update this plugin"
    tolerances.PICTURE_TIME_S = PICTURE_S
