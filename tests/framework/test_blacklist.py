"""Per-lab blacklists (issue 23, item 5): library functions a lab forbids raise in the student's code.

The declarations (``NOT_ALLOWED`` in ``tests/graded/<lab>/__init__.py``) must match the handouts and
name functions of the course's environment; a planted sdf submission that calls libigl in four
spellings is graded through ``geomlib grade`` and every one of those tests fails with the lab's
message in results.json; other routes to the same function are caught too, while given code that
uses a forbidden function keeps working.
"""

from __future__ import annotations

import importlib
import json
import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from geomlib.grading import blacklist, impl, sandbox
from geomlib.grading.errors import GradingFailure
from geomlib.grading.results import plain_text

COURSE = Path(__file__).resolve().parents[2]
LINUX = pytest.mark.skipif(sys.platform != "linux", reason="the sandbox is Linux-only")

#: A submission of the sdf lab whose Task 4 functions call libigl, each in another spelling.
SPELLINGS = """

def sign_normal(V, F, P, face, closest):
    import igl

    return np.where(igl.signed_distance(P, V, F)[0] < 0, -1.0, 1.0)  # attribute of the package


def sign_pseudonormal(V, F, P, face, closest, region, normals=None):
    from igl import signed_distance  # from-import

    return np.where(signed_distance(P, V, F)[0] < 0, -1.0, 1.0)


def sign_vote(V, F, P, *, directions=None, bvh=None):
    import importlib

    fwn = getattr(importlib.import_module("igl"), "fast_winding_number")  # importlib + getattr
    return np.where(fwn(V, F, P) > 0.5, -1.0, 1.0)


def winding_number(V, F, P, *, chunk=1 << 20):
    import igl.pyigl_core  # the compiled extension module itself

    return igl.pyigl_core.winding_number(V, F, P)
"""

MESSAGES = {
    "sign_normal": "not allowed in the sdf lab: igl.signed_distance — Task 4 asks you to write it",
    "sign_pseudonormal": "not allowed in the sdf lab: igl.signed_distance — Task 4 asks you to write it",
    "sign_vote": "not allowed in the sdf lab: igl.fast_winding_number — Task 4 asks you to write it",
    "winding_number": "not allowed in the sdf lab: igl.winding_number — Task 4 asks you to write it",
}


def _sdf_submission(dest: Path, code: str) -> Path:
    """The course's sdf stubs with ``code`` appended to ``sign.py``, as ``dest/sdf``; returns ``dest``."""
    lab = dest / "sdf"
    shutil.copytree(COURSE / "labs" / "sdf", lab, ignore=shutil.ignore_patterns("__pycache__", "README.md"))
    with open(lab / "sign.py", "a") as f:
        f.write("\n" + code)
    for p in [dest, *dest.rglob("*")]:
        p.chmod(0o755 if p.is_dir() else 0o644)
    return dest


# ---------------------------------------------------------------------------------- declarations


@pytest.mark.parametrize("lab", impl.lab_names())
def test_the_handout_lists_exactly_the_declared_functions(lab):
    declared = blacklist.declared(lab)
    sections = blacklist.handout_sections((COURSE / "labs" / lab / "README.md").read_text(encoding="utf-8"))
    if not declared:
        assert sections == [], f"labs/{lab}/README.md has a 'Not allowed' section but the lab declares no NOT_ALLOWED"
        return
    assert len(sections) == 1, f"labs/{lab}/README.md needs one 'Not allowed' section (has {len(sections)})"
    level = len(sections[0]) - len(sections[0].lstrip("#"))
    expected = blacklist.handout_section(declared, level)
    assert sections[0] == expected, (
        f"labs/{lab}/README.md's 'Not allowed' section differs from tests/graded/{lab}/__init__.py's "
        f"NOT_ALLOWED; it should read:\n{expected}"
    )


def test_the_labs_where_a_library_does_the_task_declare_a_blacklist():
    for lab in ("subdivision", "simplification", "remeshing", "sdf", "denoise", "vdm", "shadows"):
        assert blacklist.declared(lab), f"{lab} declares no NOT_ALLOWED"
    assert blacklist.declared("sdf")["igl.signed_distance"] == "Task 4 asks you to write it"


@pytest.mark.parametrize("lab", [lab for lab in impl.lab_names() if blacklist.declared(lab)])
def test_every_declared_name_is_a_function_of_the_environment(lab):
    """A misspelt name would guard nothing: each must resolve to something callable here."""
    from geomlib.render import backend

    backend()  # pyrender's names: PyOpenGL must be imported on the headless platform (as the sandbox does)
    for name in blacklist.declared(lab):
        parts = name.split(".")
        obj = None
        for i in range(len(parts) - 1, 0, -1):
            try:
                obj = importlib.import_module(".".join(parts[:i]))
            except ImportError:
                continue
            for part in parts[i:]:
                obj = getattr(obj, part, None)
            break
        assert callable(obj), f"tests/graded/{lab}/__init__.py: {name} is not a function of the environment"


def test_a_malformed_declaration_is_refused_naming_the_file(tmp_path):
    (tmp_path / "graded" / "x").mkdir(parents=True)
    (tmp_path / "graded" / "x" / "__init__.py").write_text('NOT_ALLOWED = {"signed_distance": "no module"}\n')
    with pytest.raises(ValueError, match=r"x/__init__.py.*dotted"):
        blacklist.declared("x", tmp_path)
    (tmp_path / "graded" / "x" / "__init__.py").write_text("NOT_ALLOWED = dict(a=1)\n")
    with pytest.raises(ValueError, match="literal dict"):
        blacklist.declared("x", tmp_path)
    assert blacklist.declared("nolab", tmp_path) == {}


# ---------------------------------------------------------------------------------- the real grading path


@LINUX
@pytest.mark.slow
def test_sdf_library_calls_in_four_spellings_fail_with_the_lab_message_in_results_json(tmp_path):
    sub = _sdf_submission(tmp_path / "submission", SPELLINGS)
    results = tmp_path / "results.json"
    cmd = [sys.executable, "-m", "geomlib.cli", "grade", "--impl", str(sub), "--lab", "sdf", "--task", "4"]
    p = subprocess.run(
        [*cmd, "--results", str(results)],
        cwd=COURSE,
        env={**os.environ, "GEOMLIB_NO_FEEDBACK_PICTURES": "1"},
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert results.is_file(), p.stdout[-3000:] + p.stderr[-3000:]
    data = json.loads(results.read_text())
    for function, message in MESSAGES.items():
        tests = [t for t in data["tests"] if f"› {function} " in t["name"]]
        assert tests, f"no graded test of {function} in {[t['name'] for t in data['tests']]}"
        for t in tests:
            text = plain_text(t.get("output", ""))
            assert t["score"] == 0, f"{t['name']} earned {t['score']} with libigl's answer: {text}"
            assert message in text, f"{t['name']}: {text}"
    assert data["score"] == 0


# ---------------------------------------------------------------------------------- other routes


ROUTES = {
    "a copy of the compiled module loaded from its file": """
        import importlib.util, igl.pyigl_core
        spec = importlib.util.spec_from_file_location("igl.pyigl_core", igl.pyigl_core.__file__)
        core = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(core)
        return core.winding_number(V, F, P)
    """,
    "importlib.reload of the compiled module": """
        import importlib, igl.pyigl_core
        return importlib.reload(igl.pyigl_core).winding_number(V, F, P)
    """,
    "the module's __dict__ through sys.modules": """
        import sys, igl
        return sys.modules["igl"].__dict__["winding_number"](V, F, P)
    """,
    "a fresh import after removing it from sys.modules": """
        import sys
        for name in [m for m in sys.modules if m == "igl" or m.startswith("igl.")]:
            del sys.modules[name]
        import igl
        return igl.winding_number(V, F, P)
    """,
    "another library calling it (trimesh)": """
        import trimesh
        return -trimesh.Trimesh(V, F, process=False).nearest.signed_distance(P)
    """,
    "a thread pool": """
        import concurrent.futures, igl
        with concurrent.futures.ThreadPoolExecutor(1) as ex:
            return ex.submit(igl.winding_number, V, F, P).result()
    """,
    "code compiled under a given file's name": """
        ns = {"V": V, "F": F, "P": P}
        exec(compile("import igl\\nr = igl.winding_number(V, F, P)", GIVEN_FILE, "exec"), ns)
        return ns["r"]
    """,
    "a forbidden geomlib function": """
        from geomlib.geometry import ray_cast
        return ray_cast(V, F, P, np.tile([1.0, 0.0, 0.0], (len(P), 1)))[1]
    """,
}


def _winding_submission(dest: Path, body: str) -> Path:
    body = textwrap.dedent(body).replace("GIVEN_FILE", repr(str(COURSE / "labs" / "sdf" / "truth.py")))
    code = "\ndef winding_number(V, F, P, *, chunk=1 << 20):\n" + textwrap.indent(body, "    ") + "\n"
    return _sdf_submission(dest, code) / "sdf"


def _mesh():
    from geomlib import datasets

    V, F = datasets.icosphere(1)
    P = np.random.default_rng(0).random((5, 3)) - 0.5
    return V, F, P


@LINUX
@pytest.mark.slow
@pytest.mark.parametrize("route", list(ROUTES))
def test_other_routes_to_a_forbidden_function_are_caught(tmp_path, route):
    lab = _winding_submission(tmp_path / "sub", ROUTES[route])
    with pytest.raises(GradingFailure, match="not allowed in the sdf lab: "):
        sandbox.call(lab, "sdf", "winding_number", _mesh())


@LINUX
@pytest.mark.slow
def test_given_code_keeps_using_a_forbidden_function(tmp_path):
    """The given ``truth.mesh_visibility`` casts rays with ``geomlib.geometry.ray_cast`` (forbidden in
    sdf): called from the student's code it still works; the grader's own process is untouched."""
    body = """
        from _graded_sdf.truth import mesh_visibility
        return mesh_visibility(V, F, P, np.array([3.0, 0.0, 0.0]), 0.1, n=8)
    """
    lab = _winding_submission(tmp_path / "sub", body)
    V, F, P = _mesh()
    got = sandbox.call(lab, "sdf", "winding_number", (V, F, P))
    assert got.shape == (len(P),) and np.all((got >= 0) & (got <= 1))
    import igl

    assert igl.winding_number(V, F, P).shape == (len(P),)  # the grader's process is not guarded
