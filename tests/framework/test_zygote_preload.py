"""The zygote imports numba (a quarter second of CPU) only for a lab whose course stubs use it (issue 26,
item 4: ``geomlib grade --task N`` starts a new zygote every time), and still for such a lab, so that its
workers do not import numba per call; without known stubs, everything is preloaded.

Every scenario needs a zygote of its own (what it preloaded is the point), but not an interpreter of its
own: one subprocess (:func:`scenarios`) plays them all, stopping its zygote between two, and each test
reads its own scenario's answer (0.4 s of CPU saved per scenario)."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="the sandbox is Linux-only")

SCRIPT = """
import json, os, sys
from pathlib import Path
from geomlib.grading import sandbox
from geomlib.grading.sandbox import LabProxy


def preload(root, stub_import, modules):
    stubs, lab = root / "stubs" / "prelab", root / "prelab"
    stubs.mkdir(parents=True)
    lab.mkdir()
    given = stub_import + "\\n" if stub_import not in ("", "none") else ""
    (stubs / "ops.py").write_text(given + "def loaded():\\n    raise NotImplementedError('Task 1')\\n")
    # Loaded before the lab's package: by the zygote (the stub's own import runs in the worker, after).
    (lab / "ops.py").write_text(
        "import sys\\n\\ndef loaded():\\n    names = list(sys.modules)\\n"
        f"    return [m in names and names.index(m) < names.index('_graded_prelab') for m in {modules!r}]\\n"
    )
    if stub_import != "none":
        os.environ["GEOMLIB_STUBS"] = str(root / "stubs")
    return LabProxy("prelab", lab, timeout=120).loaded()


def graded_in_place(root, stub_import, modules):
    # The course's stubs graded themselves (a student's labs/<lab>, `--impl labs`): no other stubs.
    stubs = root / "stubs" / "prelab"
    stubs.mkdir(parents=True)
    (stubs / "ops.py").write_text(
        (stub_import + "\\n" if stub_import else "") + "import sys\\n\\ndef loaded():\\n    names = list(sys.modules)\\n"
        f"    return [m in names and names.index(m) < names.index('_graded_prelab') for m in {modules!r}]\\n"
    )
    os.environ["GEOMLIB_STUBS"] = str(root / "stubs")
    return LabProxy("prelab", stubs, timeout=120).loaded()


def gl(root, first):
    stubs, lab = root / "stubs" / "gllab", root / "gllab"
    for folder in (stubs, lab):
        (folder / "shaders").mkdir(parents=True)
    (stubs / "ops.py").write_text("def loaded():\\n    raise NotImplementedError('Task 1')\\n")
    (stubs / "glops.py").write_text(
        "from geomlib import gl\\n\\n\\ndef gl_loaded():\\n    raise NotImplementedError('Task 2')\\n"
    )
    (stubs / "uses_glops.py").write_text(
        "from .glops import gl_loaded\\n\\n\\ndef via():\\n    raise NotImplementedError('Task 3')\\n"
    )
    body = "import sys\\n\\n\\ndef {}():\\n    return ['OpenGL.GL' in sys.modules]\\n"  # before the stub's imports
    (lab / "ops.py").write_text(body.format("loaded"))
    (lab / "glops.py").write_text(body.format("gl_loaded"))
    (lab / "uses_glops.py").write_text(body.format("via"))
    os.environ["GEOMLIB_STUBS"] = str(root / "stubs")
    proxy = LabProxy("gllab", lab, timeout=120)
    return [getattr(proxy, first)()[0], proxy.loaded()[0]]


def per_call(root):
    # scipy.ndimage imported by the stubs' truth.py only: preloaded for the calls into truth.py only.
    stubs, lab = root / "stubs" / "calllab", root / "calllab"
    stubs.mkdir(parents=True)
    lab.mkdir()
    (stubs / "truth.py").write_text(
        "from scipy import ndimage\\n\\n\\ndef checked():\\n    raise NotImplementedError('Task 2')\\n"
    )
    (stubs / "ops.py").write_text("def plain():\\n    raise NotImplementedError('Task 1')\\n")
    body = "import sys\\n\\n\\ndef {}():\\n    return ['scipy.ndimage' in sys.modules]\\n"  # before the stub's own imports
    (lab / "truth.py").write_text(body.format("checked"))
    (lab / "ops.py").write_text(body.format("plain"))
    os.environ["GEOMLIB_STUBS"] = str(root / "stubs")
    proxy = LabProxy("calllab", lab, timeout=120)
    return [proxy.plain()[0], proxy.checked()[0]]


out, zygotes = {}, set()
for name, (kind, *args) in json.loads(sys.argv[2]).items():
    os.environ.pop("GEOMLIB_STUBS", None)
    play = {"preload": preload, "in-place": graded_in_place, "gl": gl, "per-call": per_call}[kind]
    out[name] = play(Path(sys.argv[1]) / name, *args)
    zygotes.add(sandbox._STATE["zygote"].proc.pid)
    sandbox.shutdown()  # the next scenario starts a zygote of its own
out["zygotes"] = len(zygotes)
print(json.dumps(out))
"""

#: Scenario name -> ("preload", the stub's import ("" none, "none": no known stubs), modules checked),
#: ("in-place", the same, the stubs graded themselves), ("gl", the function called first) or
#: ("per-call",): a plain call, then a call into the stub module that imports scipy.ndimage. A lab
#: whose stubs import none of them checks them all at once.
SCENARIOS = {
    "plain": ("preload", "", ["numba", "scipy.spatial", "scipy.ndimage", "scipy.sparse.linalg"]),
    "njit": ("preload", "from numba import njit", ["numba"]),
    "jit": ("preload", "from geomlib.jit import use_cache_folder", ["numba"]),
    "no-stubs": ("preload", "none", ["numba"]),
    "in-place": ("in-place", "", ["numba", "scipy.spatial", "scipy.ndimage", "scipy.sparse.linalg"]),
    "in-place-njit": ("in-place", "from numba import njit", ["numba"]),
    "scipy.spatial": ("preload", "import scipy.spatial", ["scipy.spatial"]),
    "scipy.ndimage": ("preload", "import scipy.ndimage", ["scipy.ndimage"]),
    "scipy.sparse.linalg": ("preload", "import scipy.sparse.linalg as spla", ["scipy.sparse.linalg"]),
    "gl-loaded": ("gl", "loaded"),
    "gl-gl_loaded": ("gl", "gl_loaded"),
    "gl-via": ("gl", "via"),
    "per-call": ("per-call",),
}


@pytest.fixture(scope="module")
def scenarios(tmp_path_factory) -> dict:
    """Each scenario's answer, played in one subprocess."""
    root = tmp_path_factory.mktemp("preload")
    p = subprocess.run(
        [sys.executable, "-c", SCRIPT, str(root), json.dumps(SCENARIOS)], capture_output=True, text=True, timeout=600
    )
    assert p.returncode == 0, p.stderr[-2000:]
    out = json.loads(p.stdout.strip().splitlines()[-1])
    assert out.pop("zygotes") == len(SCENARIOS), "two scenarios shared a zygote"
    return out


def test_a_worker_of_a_lab_without_numba_starts_without_it(scenarios):
    assert not scenarios["plain"][0], "the zygote imported numba for a lab whose stubs do not use it"


@pytest.mark.parametrize(
    "scenario", ["njit", "jit"], ids=["from numba import njit", "from geomlib.jit import use_cache_folder"]
)
def test_a_worker_of_a_numba_lab_inherits_numba(scenarios, scenario):
    assert scenarios[scenario] == [True], "a numba lab's worker imported numba itself"


def test_without_known_stubs_everything_is_preloaded(scenarios):
    assert scenarios["no-stubs"] == [True]


def test_stubs_graded_in_place_preload_what_their_own_files_import(scenarios):
    """``geomlib grade --impl labs`` and a student's grade of their labs/<lab>: the graded folder is
    the course's stubs, so no other stubs say what the lab uses; its own imports do (numba's import
    and warm-up cost 1.5 s of CPU at every start of the grader, for a lab without it too)."""
    assert scenarios["in-place"] == [False, False, False, False], "the zygote preloaded for a lab that imports none"
    assert scenarios["in-place-njit"] == [True], "a numba lab graded in place: its worker imported numba itself"


@pytest.mark.parametrize("module", ["scipy.spatial", "scipy.ndimage", "scipy.sparse.linalg"])
def test_scipy_modules_are_preloaded_for_the_labs_that_use_them(scenarios, module):
    """Like numba: 0.08, 0.05 and 0.1 s of CPU at every start of the zygote, for subdivision too, whose
    stubs use none; a lab whose stubs import them (vdm, sdf, shadows' truth) still has them in
    every worker."""
    plain = dict(zip(SCENARIOS["plain"][2], scenarios["plain"], strict=True))
    assert not plain[module], f"the zygote imported {module} for a lab without it"
    assert scenarios[module] == [True], f"a worker imported {module} itself"


@pytest.mark.parametrize("first", ["loaded", "gl_loaded", "via"])
def test_pyopengl_is_preloaded_at_the_first_call_that_may_use_it(scenarios, first):
    """A lab with shaders/: the zygote imports PyOpenGL (0.2 s of CPU) before the first call whose
    stub module imports geomlib.gl, itself or through the lab's modules it imports, and from then on
    for every call; not for calls before that (shadows' --task 3 runs no shader)."""
    at_first, after = scenarios[f"gl-{first}"]
    expected = first != "loaded"
    assert (at_first, after) == (expected, expected), (first, at_first, after)


def test_whether_a_call_may_use_opengl_is_worked_out_once(tmp_path, monkeypatch):
    """The zygote asks at every call of a lab with shaders/ until PyOpenGL is loaded (for all of
    shadows' --task 3, which runs no shader): the stubs are walked once per function, not per call
    (4-12 ms each)."""
    from geomlib.grading import worker

    stubs = tmp_path / "gllab"
    stubs.mkdir()
    (stubs / "ops.py").write_text("from . import glops\n\n\ndef plain():\n    raise NotImplementedError('Task 1')\n")
    (stubs / "glops.py").write_text(
        "from geomlib import gl\n\n\ndef drawn():\n    raise NotImplementedError('Task 2')\n"
    )
    worker.prepare_stubs(str(stubs))
    assert worker._may_use_gl(str(stubs), "plain") and worker._may_use_gl(str(stubs), "drawn")
    walked = []
    real = worker.ast.walk
    monkeypatch.setattr(worker.ast, "walk", lambda node: (walked.append(node), real(node))[1])
    assert worker._may_use_gl(str(stubs), "plain") and worker._may_use_gl(str(stubs), "drawn")
    assert not walked, "the stubs were walked again"


def test_a_module_is_preloaded_for_the_calls_whose_stub_module_imports_it(scenarios):
    """Shadows' stubs import scipy.ndimage (0.25 s of CPU) in truth.py only, whose helper no graded call
    runs: a call into another module starts without it, a call into truth.py still inherits it."""
    assert scenarios["per-call"] == [False, True]
