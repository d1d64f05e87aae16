"""The order in which ``./run tests`` hands test modules to its pytest-xdist workers.

Not part of any release (``tests/conftest.py`` is the one the graded tests need). ``./run tests``
runs ``--dist loadfile --no-loadscope-reorder``: a module stays on one worker (its module fixtures
are built once) and modules are handed out in collection order, which this hook makes longest
first (:data:`SECONDS`). xdist's own order (most tests first) handed the long framework modules
out last, and one worker ran them alone while the other idled. In a run without workers this file
changes nothing.
"""

from __future__ import annotations

import pytest

#: Seconds a module takes: the sum of its tests' durations in CI's run of 2026-11-26 (2 workers).
#: Modules not listed are short and follow, in collection order.
SECONDS: dict[str, float] = {
    "tests/solutions/test_deterministic.py": 215,
    "tests/framework/test_release_course.py": 140,
    "tests/test_figures_reproduce.py": 125,
    "tests/framework/test_feedback_pictures.py": 105,
    "tests/solutions/test_simplification.py": 70,
    "tests/framework/test_hostile.py": 80,
    "tests/test_course.py": 75,
    "tests/test_notebooks.py": 60,
    "tests/framework/test_fresh_root.py": 57,
    "tests/framework/test_fresh_student.py": 54,
    "tests/framework/test_planted_labs.py": 43,
    "tests/framework/test_audit.py": 42,
    "tests/framework/test_batch.py": 41,
    "tests/solutions/test_sdf.py": 37,
}


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    if not hasattr(config, "workerinput"):  # only an xdist worker's collection is scheduled
        return
    order = {id(item): i for i, item in enumerate(items)}
    items.sort(key=lambda item: (-SECONDS.get(item.nodeid.split("::", 1)[0], 0.0), order[id(item)]))
