"""The order in which ``./run tests`` hands test modules to its pytest-xdist workers.

Not part of any release (``tests/conftest.py`` is the one the graded tests need). ``./run tests``
runs ``--dist loadfile --no-loadscope-reorder``: a module stays on one worker (its module fixtures
are built once) and modules are handed out in collection order, which this hook makes longest
first (:data:`SECONDS`). xdist's own order (most tests first) handed the long framework modules
out last, and one worker ran them alone while the other idled. In a run without workers this file
changes nothing.
"""

from __future__ import annotations

import os
import sys
import traceback

import pytest

#: Seconds one feedback picture may take in the suite's runs (``GEOMLIB_PICTURE_TIME_LIMIT``, default
#: 20 s). A picture takes about 2 s on a quiet machine, but the suite runs on 2 shared cores beside
#: other CPU-bound processes, where one took more than 20 s and a test that expects a picture failed
#: for the machine's speed: x10 above a loaded machine's need, still a limit for hangs. Set here, it
#: reaches in-process runs and every grading subprocess that inherits the environment.
PICTURE_TIME_LIMIT_S = "300"


def pytest_configure(config: pytest.Config) -> None:
    os.environ.setdefault("GEOMLIB_PICTURE_TIME_LIMIT", PICTURE_TIME_LIMIT_S)
    sys.meta_path.insert(0, _OpenGLOnlyOnAHeadlessPlatform())


class _OpenGLOnlyOnAHeadlessPlatform:
    """PyOpenGL binds its platform once, at its first import: imported while ``PYOPENGL_PLATFORM`` is
    unset, it takes GLX and every later render in that process fails ("PyOpenGL was imported before a
    headless platform was chosen"). Two loaded CI runs lost 8 and 19 tests of one xdist worker that
    way without showing who imported it. This guard makes that import fail where it happens, with its
    stack, so the test that does it is the one that fails (geomlib.render.backend() sets the variable
    before it imports OpenGL, so the library's own path is never refused)."""

    def find_spec(self, name, path=None, target=None):
        if name == "OpenGL" and not os.environ.get("PYOPENGL_PLATFORM"):
            where = "".join(traceback.format_stack(limit=12)[:-1])
            raise ImportError(
                "OpenGL imported before a headless platform was chosen (PYOPENGL_PLATFORM is unset); "
                f"go through geomlib.render.backend()/import_pyrender(). Imported from:\n{where}"
            )
        return None


#: Seconds a module takes: the sum of its tests' durations in CI's run of 2026-11-26 (2 workers);
#: test_release_course, test_hostile, test_course and test_audit lowered since by what their
#: repetitions cost (issue 25 item 5: release --no-check, one hung call instead of ~20, refs check
#: --no-rerun and numba preloaded in the zygote, operator mutants compiled once; estimates from CPU
#: time measured on a loaded machine). Modules not listed are short and follow, in collection order.
SECONDS: dict[str, float] = {
    "tests/solutions/test_deterministic.py": 215,
    "tests/framework/test_release_course.py": 115,
    "tests/test_figures_reproduce.py": 125,
    "tests/framework/test_feedback_pictures.py": 105,
    "tests/solutions/test_simplification.py": 70,
    "tests/framework/test_hostile.py": 50,
    "tests/test_course.py": 55,
    "tests/test_notebooks.py": 60,
    "tests/framework/test_fresh_root.py": 57,
    "tests/framework/test_fresh_student.py": 54,
    "tests/framework/test_planted_labs.py": 43,
    "tests/framework/test_audit.py": 30,
    "tests/framework/test_batch.py": 41,
    "tests/solutions/test_sdf.py": 37,
}


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    if not hasattr(config, "workerinput"):  # only an xdist worker's collection is scheduled
        return
    order = {id(item): i for i, item in enumerate(items)}
    items.sort(key=lambda item: (-SECONDS.get(item.nodeid.split("::", 1)[0], 0.0), order[id(item)]))
