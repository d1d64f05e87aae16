"""How ``./run tests`` shares the suite between its pytest-xdist workers.

Not part of any release (``tests/conftest.py`` is the one the graded tests need). ``./run tests``
runs ``--dist loadfile --no-loadscope-reorder``, and :func:`pytest_xdist_make_scheduler` turns the
files into units of work (:func:`work_unit`: a module, or in the modules of :data:`SPLIT` a single
test). A unit goes to one worker, so a module's fixtures are built once, and units are handed out
in collection order, which :func:`pytest_collection_modifyitems` makes longest first (:data:`SECONDS`). With ``--dist loadfile`` the 18 notebook runs were one unit of about 520 s on
one worker (of an 869 s run); xdist's own order (most tests first) handed the long framework modules
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

#: Seconds a call into the implementation may take in the suite's own runs of the graded tests
#: (``GEOMLIB_TIME_LIMIT``; a graded test's limit is 30 s, or 60 s where it says so, measured on the
#: wall clock). The slowest calls of the solutions need about 25 s on a quiet 2-core machine (the
#: first call of a run compiles the lab's kernels); at a load of 18, 16 of remeshing's 35 graded tests
#: failed with "did not finish within 30 s (time limit)". The suite checks answers, not speed (that
#: is bench/'s job), so its limit is for hangs: x10. Tests of the time-out itself set their own limit
#: (test_hostile, test_planted_labs, test_sandbox, test_batch). Only for a run without ``--impl``
#: (the suite): ``geomlib grade`` and the autograder name their implementation and keep their limits.
TIME_LIMIT_S = "300"


#: Modules the suite never imports: jsonschema (``results.json``'s schema; nbformat's, under nbclient)
#: imports the optional ``rfc3987_syntax`` when installed (jupyterlab's jupyter-events asks for
#: jsonschema's format extras), which builds about 35 Lark parsers at import: 3.2 s of CPU in every
#: test process that validates a result or runs a notebook (python-jsonschema/jsonschema#1428). It
#: serves only the ``iri`` format, which no schema here uses and which ``jsonschema.validate`` does not
#: check (formats are checked only with a ``format_checker``): jsonschema skips it when it is missing.
NOT_IMPORTED = ("rfc3987_syntax",)


def pytest_configure(config: pytest.Config) -> None:
    for name in NOT_IMPORTED:
        sys.modules.setdefault(name, None)  # None: "import name" raises ImportError
    os.environ.setdefault("GEOMLIB_PICTURE_TIME_LIMIT", PICTURE_TIME_LIMIT_S)
    if config.getoption("--impl", None) is None and config.getoption("--time-limit", None) is None:
        os.environ.setdefault("GEOMLIB_TIME_LIMIT", TIME_LIMIT_S)  # for the suite's grading subprocesses
        config.option.time_limit = float(os.environ["GEOMLIB_TIME_LIMIT"])  # the option's default was read already
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


#: Modules whose tests share no module fixture and each take long enough to be worth a worker of
#: their own: ``./run tests`` hands them out test by test (one notebook, one stubs grade). Any other
#: module stays on one worker (:func:`work_unit`): its module fixtures are built once, and its graded
#: tests compile a lab's kernels in one sandbox. In the quiet CI run of 2026-11-27 (869 s) the 18
#: notebook runs, about 520 s, ran on one worker as one module.
SPLIT = {
    "tests/test_course.py",
    "tests/framework/test_audit.py",
    "tests/framework/test_batch.py",
    "tests/framework/test_feedback_pictures.py",
    "tests/framework/test_hostile.py",
    "tests/framework/test_planted_labs.py",
    "tests/solutions/test_simplification.py",
}
#: Modules whose module fixture is built per value of one parameter (the figures of one lab, drawn
#: once for the comparison and the captions; one kernel running a notebook on the stubs and the
#: solutions): one unit per value.
SPLIT_BY = {"tests/test_figures_reproduce.py": "lab", "tests/test_notebooks.py": "path"}

#: Seconds a unit of work (:func:`work_unit`) takes: its tests' durations in the quiet CI run of
#: 2026-11-27 (869 s; modules and tests below its 30 slowest estimated from the loaded run). Only the
#: order matters: the longest are handed out first and the short ones fill in. Units not listed are
#: short and follow, in collection order. Rescaled since by the CPU time measured before and after a
#: change to the unit (cgroup, same load): test_course_object x0.62, test_deterministic x0.8 (wall).
SECONDS: dict[str, float] = {
    "tests/solutions/test_deterministic.py": 105,
    "tests/framework/test_release_course.py": 80,
    # a notebook's two runs, stubs and solutions, in one kernel (sum of the two tests before)
    "tests/test_notebooks.py:remeshing": 133,
    "tests/test_notebooks.py:shadows": 89,
    "tests/test_notebooks.py:sdf": 59,
    "tests/test_notebooks.py:maps": 49,
    "tests/test_notebooks.py:vdm": 44,
    "tests/test_notebooks.py:relief": 41,
    "tests/test_notebooks.py:denoise": 39,
    "tests/test_notebooks.py:subdivision": 35,
    "tests/test_notebooks.py:simplification": 32,
    "tests/graded/remeshing": 55,  # test_remeshing.py 50 s and its hidden tests
    "tests/framework/test_planted_labs.py::test_relief_hanging_shader_time_out_names_the_shader_the_task_and_the_cause": 43,
    "tests/framework/test_fresh_root.py": 29,
    "tests/framework/test_batch.py::test_grade_all_as_root_on_the_documented_path_runs_student_code_as_the_sandbox_user": 25,
    "tests/solutions/test_sdf.py": 25,
    "tests/framework/test_fresh_student.py": 21,
    "tests/framework/test_hostile.py::test_detached_children_forged_lines_and_tampering_do_not_survive_the_call": 20,
    "tests/test_figures_reproduce.py:sdf": 18,
    "tests/test_figures_reproduce.py:relief": 18,
    "tests/test_figures_reproduce.py:remeshing": 16,
    "tests/framework/test_course_object.py": 10,
    "tests/test_figures_reproduce.py:simplification": 15,
    "tests/framework/test_audit.py::test_every_mutant_changes_one_block_only_and_compiles[remeshing]": 15,
    "tests/test_course.py::test_solutions_reproduce_the_stored_references": 15,
    "tests/test_figures_reproduce.py:vdm": 12,
    "tests/test_figures_reproduce.py:shadows": 10,
}


def work_unit(nodeid: str) -> str:
    """What ``./run tests`` hands to one worker as a whole: the test itself in a module of
    :data:`SPLIT`, the module and the parameter's value (``module:value``) in :data:`SPLIT_BY`, a
    lab's folder of graded tests (``tests/graded/<lab>``), else the module."""
    module = nodeid.split("::", 1)[0]
    if module in SPLIT:
        return nodeid
    if module in SPLIT_BY and nodeid.endswith("]") and "[" in nodeid:
        return f"{module}:{nodeid[nodeid.index('[') + 1 : -1]}"  # the test's one parameter
    if module.startswith("tests/graded/") and module.count("/") == 3:
        # A lab's graded modules (public, hidden, GLSL) on one worker: one sandbox snapshot of the
        # solutions and one compile of its kernels. As two units, test_sdf.py and test_sdf_hidden.py
        # (adjacent, short) ran at once on two workers and both compiled sdf's kernels.
        return module.rsplit("/", 1)[0]
    return module


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    if not hasattr(config, "workerinput"):  # only an xdist worker's collection is scheduled
        return
    order = {id(item): i for i, item in enumerate(items)}
    items.sort(key=lambda item: (-SECONDS.get(work_unit(item.nodeid), 0.0), order[id(item)]))


# optionalhook: a grading run (geomlib grade, check()) starts pytest with plugin autoload off, so
# xdist and its hook specs are absent there; without the flag pluggy refuses the unknown hook and
# no graded test runs at all.
@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config: pytest.Config, log):
    """``--dist loadfile`` with the units of :func:`work_unit` instead of whole files. (Not xdist's
    ``--dist loadgroup``: under pytest 9 its ``xdist_group`` marks are silently ignored, since it
    renames ``item._nodeid``, which pytest no longer reads.)"""
    if config.getvalue("dist") != "loadfile":
        return None
    from xdist.scheduler import LoadFileScheduling

    class UnitScheduling(LoadFileScheduling):
        def _split_scope(self, nodeid: str) -> str:
            return work_unit(nodeid)

    return UnitScheduling(config, log)
