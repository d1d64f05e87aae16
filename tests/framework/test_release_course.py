"""The real course, released and graded the way Gradescope does it (issue 13, items 1-3 and 5).

One lab (subdivision: the quickest to grade) is released with ``geomlib release``; its autograder
zip is unzipped into a temporary ``GEOMLIB_AUTOGRADER_ROOT``; ``setup.sh`` installs it (the real
``uv sync --frozen``, offline from the uv cache; apt is skipped when the packages are present);
``run_autograder`` then grades four submissions — the solutions, the stubs, a hostile one and one
that looks the public stored outputs up — as root with the drop to ``nobody``, as on Gradescope.
Every results.json is validated against the Gradescope schema.
"""

from __future__ import annotations

import ast
import json
import os
import shutil
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

import pytest

from geomlib.grading.results import validate_results

pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[2]
LAB = "subdivision"
IS_ROOT = os.geteuid() == 0


def _env(**extra) -> dict:
    env = {k: v for k, v in os.environ.items() if k not in ("GEOMLIB_ROOT", "VIRTUAL_ENV", "UV_PROJECT_ENVIRONMENT")}
    env.update(extra)
    return env


@pytest.fixture(scope="module")
def base():
    d = Path(tempfile.mkdtemp(prefix="geomlib-course-release-"))
    d.chmod(0o755)  # the sandbox user must be able to reach the autograder root below it
    yield d
    # The installed environment holds thousands of files: remove it without making the suite wait.
    subprocess.Popen(
        ["rm", "-rf", str(d)], start_new_session=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
    )


@pytest.fixture(scope="module")
def released(base) -> Path:
    out = base / "dist"
    # --no-check: release's grading of the solutions before it packages is repetition here (the suite
    # grades them in tests/graded, and test_solutions_score_every_point through this autograder);
    # that check is tested on a copy of this course by test_release_refuses.py.
    p = subprocess.run(
        [sys.executable, "-m", "geomlib.cli", "release", str(out), "--lab", LAB, "--no-check"],
        cwd=ROOT,
        env=_env(),
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert p.returncode == 0, p.stdout + p.stderr
    return out


@pytest.fixture(scope="module")
def autograder(base, released) -> Path:
    if shutil.which("uv") is None:
        # CI (CI=true) must run these: `./run tests` puts the uv it found or installed on the PATH.
        if os.environ.get("CI", "").lower() in ("1", "true", "yes"):
            pytest.fail(
                "uv is not on the PATH under CI=true: run the suite with `./run tests`, which puts its uv there"
            )
        pytest.skip("uv is not installed")
    root = base / "autograder"
    (root / "source").mkdir(parents=True)
    root.chmod(0o755)
    with zipfile.ZipFile(released / f"autograder-{LAB}.zip") as z:
        z.extractall(root / "source")
    env = _env(GEOMLIB_AUTOGRADER_ROOT=str(root), UV_OFFLINE="1")
    if not IS_ROOT:
        env["GEOMLIB_SANDBOX_USER"] = ""
    p = subprocess.run(
        ["bash", str(root / "source" / "setup.sh")], env=env, capture_output=True, text=True, timeout=600
    )
    assert p.returncode == 0, f"setup.sh failed:\n{p.stdout[-3000:]}\n{p.stderr[-3000:]}"
    assert "ready to grade" in p.stdout
    # Bytecode compiled for the sandbox user, who cannot write it: a module nothing has imported yet.
    site = root / "source" / ".venv" / "lib"
    assert list(site.glob("python3*/site-packages/numpy/f2py/__pycache__/crackfortran.*.pyc")), p.stdout[-3000:]
    return root


def _run(root: Path, fill, **extra_env) -> tuple[dict, str]:
    """Put a submission in place with ``fill(submission_dir)``, run run_autograder, return (results, log)."""
    for name in ("submission", "results"):
        shutil.rmtree(root / name, ignore_errors=True)
    (root / "submission").mkdir()
    fill(root / "submission")
    subprocess.run(["chmod", "-R", "a+rX", str(root / "submission")], check=True)
    env = _env(GEOMLIB_AUTOGRADER_ROOT=str(root), **extra_env)
    # A minimal PATH without sbin, as cron or `env -i` give: run_autograder must still find runuser.
    env["PATH"] = "/usr/bin:/bin"
    if not IS_ROOT:
        env["GEOMLIB_SANDBOX_USER"] = ""
    p = subprocess.run(
        ["bash", str(root / "source" / "run_autograder")], env=env, capture_output=True, text=True, timeout=900
    )
    assert p.returncode == 0, p.stdout[-3000:] + p.stderr[-3000:]
    results = json.loads((root / "results" / "results.json").read_text())
    validate_results(results)
    return results, p.stdout


@pytest.fixture(scope="module")
def points():
    from geomlib.grading.points import points_by_part

    return points_by_part([LAB])[LAB]


# ---------------------------------------------------------------------------------- the zip


def test_autograder_zip_grades_only_its_lab(released):
    with zipfile.ZipFile(released / f"autograder-{LAB}.zip") as z:
        names = z.namelist()
    assert {"setup.sh", "run_autograder", "README.md", "pyproject.toml", "uv.lock"} <= set(names)
    labs = {n.split("/")[1] for n in names if n.startswith("labs/")}
    graded = {n.split("/")[2] for n in names if n.startswith("tests/graded/") and n.count("/") > 2}
    refs = {n.split("/")[2] for n in names if n.startswith("tests/reference/")}
    assert labs == graded == refs == {LAB}
    assert f"tests/graded/{LAB}/cases_hidden.py" in names
    assert any(n.startswith(f"tests/reference/{LAB}/hidden/") for n in names)
    assert not any(n.startswith(("solutions/", "notebooks/", "tests/framework", "tests/unit")) for n in names)


def test_hidden_material_is_readable_by_root_only(autograder):
    src = autograder / "source"
    hidden = [src / f"tests/graded/{LAB}/cases_hidden.py", src / f"tests/graded/{LAB}/test_{LAB}_hidden.py"]
    hidden += sorted((src / f"tests/reference/{LAB}/hidden").glob("*"))
    for p in hidden:
        assert p.stat().st_mode & 0o077 == 0, p
    if IS_ROOT:
        for p in hidden[:3]:
            r = subprocess.run(["runuser", "-u", "nobody", "--", "cat", str(p)], capture_output=True)
            assert r.returncode != 0 and not r.stdout, p


# ---------------------------------------------------------------------------------- submissions


def test_solutions_score_every_point(autograder, points):
    r, _ = _run(autograder, lambda sub: shutil.copytree(ROOT / "solutions" / LAB, sub / "labs" / LAB))
    total = sum(p + h for p, h in points.values())
    assert r["score"] == total == sum(t["max_score"] for t in r["tests"])
    assert all(t["status"] == "passed" for t in r["tests"]), [t["name"] for t in r["tests"] if t["status"] != "passed"]
    assert any(t["visibility"] == "hidden" for t in r["tests"])


#: The picture cap this test sets through run_autograder's GEOMLIB_MAX_FEEDBACK_PICTURES (default 8).
#: A picture costs about 1.5 s of CPU and this submission has more failures that can be drawn than 8
#: (docs/autograder.md: 14), so the default drew 8 (12 s) where 2 show the same: the first failures
#: get their picture inlined, the cap stops the drawing, and the file stays small.
PICTURE_CAP = 2


def test_run_autograder_caps_feedback_pictures_at_8_by_default(released):
    """The cap's default (what Gradescope runs with); the cap at work is the test below."""
    with zipfile.ZipFile(released / f"autograder-{LAB}.zip") as z:
        script = z.read("run_autograder").decode()
    assert 'export GEOMLIB_MAX_FEEDBACK_PICTURES="${GEOMLIB_MAX_FEEDBACK_PICTURES-8}"' in script


def test_a_wrong_weight_gets_feedback_pictures_inlined_up_to_the_cap(autograder, points):
    """A wrong odd-vertex weight (Task 1): the failing tests name it, the first few carry their feedback
    picture inside results.json (Gradescope serves no files), and the cap keeps the file small."""

    def fill(sub):
        lab = sub / "labs" / LAB
        shutil.copytree(ROOT / "solutions" / LAB, lab)
        src = (lab / "loop.py").read_text()
        wrong = src.replace("np.tile([3 / 8, 3 / 8, 1 / 8, 1 / 8]", "np.tile([3 / 8, 3 / 8, 1 / 7, 1 / 8]")
        assert wrong != src, "the planted line is gone from the solution: update this test"
        (lab / "loop.py").write_text(wrong)

    r, _ = _run(autograder, fill, GEOMLIB_MAX_FEEDBACK_PICTURES=str(PICTURE_CAP))
    failed = [t for t in r["tests"] if t["status"] == "failed"]
    assert failed and r["score"] < sum(p + h for p, h in points.values())
    # More failures than the cap, so the cap is what stops the pictures.
    assert len(failed) > PICTURE_CAP + 4, len(failed)
    pictured = [t for t in failed if t.get("output_format") == "html"]
    assert 1 <= len(pictured) <= PICTURE_CAP, len(pictured)
    assert all("data:image/png;base64," in t["output"] for t in pictured)
    size = (autograder / "results" / "results.json").stat().st_size
    assert size < PICTURE_CAP * 450_000, size


def test_stubs_score_zero(autograder):
    # Submitted as the bare lab folder (no labs/ around it): both layouts are accepted.
    r, _ = _run(autograder, lambda sub: shutil.copytree(ROOT / "labs" / LAB, sub / LAB))
    assert r["score"] == 0
    pointed = [t for t in r["tests"] if t["max_score"] > 0]
    assert pointed and all("not implemented yet" in t["output"] for t in pointed)


HOSTILE = """

import os as _os
import pathlib as _pathlib

_SRC = _pathlib.Path(_os.environ.get("GEOMLIB_ROOT", "/autograder/source"))


def _attack():
    got = []
    for rel in ("tests/graded/{lab}/cases_hidden.py", "tests/reference/{lab}/hidden/manifest.json",
                "tests/graded/{lab}/test_{lab}_hidden.py", "hidden_cases.py"):
        for base in (_SRC, _pathlib.Path(__file__).parent):
            try:
                got.append("read " + str((base / rel).read_bytes()[:20]))
            except OSError:
                pass
    for rel in ("pwned.txt", "geomlib/pwned.py", "tests/reference/{lab}/pwned.npz", "../results/results.json"):
        try:
            (_SRC / rel).write_text("pwned")
            got.append("wrote " + rel)
        except OSError:
            pass
    return got


def loop_odd_matrix(V, F):
    raise RuntimeError("attack: " + repr(_attack()))


def loop_subdivide(V, F, levels=1, weights="loop"):
    raise RuntimeError("attack: " + repr(_attack()))
"""


def test_hostile_submission_gains_nothing(autograder):
    src = autograder / "source"

    def fill(sub):
        lab = sub / "labs" / LAB
        shutil.copytree(ROOT / "labs" / LAB, lab)
        with open(lab / "loop.py", "a") as f:
            f.write(HOSTILE.replace("{lab}", LAB))
        # Links into the course: copied as links (or followed) they would expose hidden material.
        (lab / "hidden_cases.py").symlink_to(src / f"tests/graded/{LAB}/cases_hidden.py")
        (lab / "course").symlink_to(src)

    before = {p: p.stat().st_mtime for p in src.rglob("*") if p.is_file() and ".venv" not in p.parts}
    r, log = _run(autograder, fill)
    assert r["score"] == 0
    assert "not copied: course (symbolic link)" in log and "not copied: hidden_cases.py (symbolic link)" in log
    attacks = [t["output"] for t in r["tests"] if "attack:" in t["output"]]
    assert attacks, "the hostile functions did not run"
    if IS_ROOT:  # as nobody: nothing hidden read, nothing written
        assert not any("read " in a or "wrote " in a for a in attacks), attacks
    after = {p: p.stat().st_mtime for p in src.rglob("*") if p.is_file() and ".venv" not in p.parts}
    assert after == before, "the submission changed the autograder's source"


#: A case's key in the look-up table: its function and the shapes of its arguments.
KEY = """
def _key(name, values):
    import numpy as np

    shapes = []
    for v in values:
        if hasattr(v, "__len__") and not isinstance(v, str | dict):
            try:
                shapes.append(list(np.shape(v)))
            except ValueError:
                shapes.append(["ragged", len(v)])
    return name + repr(shapes)
"""

LOOKUP = (
    "\n\n"
    + KEY
    + """

def _lookup(_name, _args):
    import json
    import pathlib

    import numpy as np

    here = pathlib.Path(__file__).parent / "_answers"
    index = json.loads((here / "index.json").read_text())
    key = _key(_name, _args)
    if key not in index:
        raise NotImplementedError("lookup: this input is not among the public stored outputs")
    with np.load(here / (index[key][0] + ".npz")) as z:
        out = [z[name] for name in index[key][1]]
    return out[0] if len(out) == 1 else tuple(out)
"""
)

#: Builds the look-up table from what students get (the bundle's public cases and references): a
#: case is found again by its function and the shapes of its arguments (all a task body can see once
#: the course's given validation has run); keys shared by cases with different outputs are dropped.
BUILD_LOOKUP = (
    KEY
    + """
import inspect, json, pathlib, shutil, sys
import numpy as np
from geomlib.grading.cases import load_cases, reference_path
from geomlib.grading.impl import load_lab
out = pathlib.Path(sys.argv[1]); out.mkdir(parents=True)
lab = load_lab(sys.argv[2], "labs")
index, points, clash = {}, {}, set()
for c in load_cases(sys.argv[2], hidden=False):
    kwargs = {**c.inputs(), **c.params}
    bound = inspect.signature(getattr(lab, c.function)).bind(**kwargs)
    bound.apply_defaults()
    key = _key(c.function, list(bound.arguments.values()))
    if key in index:
        clash.add(key)
    shutil.copy(reference_path(sys.argv[2], c), out / (c.id + ".npz"))
    index[key] = [c.id, list(c.outputs)]
    points[key] = c.points
for key in clash:
    del index[key], points[key]
(out / "index.json").write_text(json.dumps(index))
print(sum(points.values()))
# The points of the instructors' course's public reference cases: in this process, which has the
# student bundle's cases loaded (load_cases leaves that course's `graded` package for this one's).
import os
os.environ["GEOMLIB_ROOT"] = sys.argv[3]
print(sum(c.points for c in load_cases(sys.argv[2], hidden=False)))
"""
)


def _lookup_submission(student: Path, sub: Path) -> tuple[float, float]:
    """The stubs, each task's ``raise NotImplementedError`` replaced by a look-up of the public stored outputs.

    The task's signature and the course's given lines before it stay (the grader uses the course's
    anyway); returns the points of the public cases the look-up can find again, and the points of
    the public reference cases of this course (not of the bundle), from the same interpreter.
    """
    lab = sub / "labs" / LAB
    shutil.copytree(student / "labs" / LAB, lab)
    env = _env(GEOMLIB_ROOT=str(student), PYTHONPATH=str(student))
    p = subprocess.run(
        [sys.executable, "-c", BUILD_LOOKUP, str(lab / "_answers"), LAB, str(ROOT)],
        env=env, check=True, timeout=300, capture_output=True, text=True, cwd=student,
    )  # fmt: skip
    findable, public_refs = (float(x) for x in p.stdout.strip().splitlines()[-2:])
    for f in lab.glob("*.py"):
        text = f.read_text()
        lines = text.splitlines()
        tree = ast.parse(text)
        tasks = []
        for node in tree.body:
            if not isinstance(node, ast.FunctionDef):
                continue
            for st in node.body:
                if isinstance(st, ast.Raise) and "NotImplementedError" in ast.unparse(st):
                    params = [a.arg for a in node.args.posonlyargs + node.args.args + node.args.kwonlyargs]
                    tasks.append((st.lineno, st.end_lineno, st.col_offset, node.name, params))
        if not tasks:
            continue
        for first, last, col, name, params in sorted(tasks, reverse=True):
            call = " " * col + f"return _lookup({name!r}, [{', '.join(params)}])"
            lines[first - 1 : last] = [call]
        f.write_text("\n".join(lines) + "\n" + LOOKUP)
    return findable, public_refs


def test_a_lookup_of_the_public_outputs_scores_below_half(autograder, released, points):
    found = {}
    r, _ = _run(autograder, lambda sub: found.setdefault("points", _lookup_submission(released / "student", sub)))
    findable = {"points": found["points"][0]}
    public_refs = found["points"][1]
    assert 0 < findable["points"] <= public_refs
    total = sum(p + h for p, h in points.values())
    missed = [
        t["name"] + ": " + t["output"][:200]
        for t in r["tests"]
        if t["status"] == "failed" and "lookup:" not in t["output"]
    ]
    not_found = [t["name"] for t in r["tests"] if t["status"] == "failed" and "lookup:" in t["output"]]
    # The look-up really works (it earns most of what it can find again; a few keys are met again by
    # inputs that a given helper reshapes), and it never earns more than the public reference cases.
    assert 0.8 * findable["points"] <= r["score"] <= public_refs, (r["score"], findable["points"], missed, not_found)
    assert r["score"] < total / 2
    per_part: dict[str, float] = {}
    for t in r["tests"]:
        per_part[t["tags"][1]] = per_part.get(t["tags"][1], 0) + t["score"]
    for part, got in per_part.items():
        pub, hid = points[part]
        assert got < (pub + hid) / 2 or pub + hid == 0, (part, got, pub, hid)
    print(f"\nlookup submission: {r['score']:g} / {total:g}")


def test_a_failure_of_the_grader_is_reported_as_the_graders(autograder):
    r, _ = _run(
        autograder,
        lambda sub: shutil.copytree(ROOT / "solutions" / LAB, sub / LAB),
        GEOMLIB_PYTHON=str(autograder / "no-such-python"),
    )
    assert r["score"] == 0 and r["tests"] == []
    assert "autograder itself failed" in r["output"] and "not a problem with your submission" in r["output"]
    assert "its Python environment does not start; run setup.sh" in r["output"], r["output"]


def test_a_submission_without_the_lab_is_told_what_to_upload(autograder):
    r, _ = _run(autograder, lambda sub: (sub / "notes.txt").write_text("hello"))
    assert r["score"] == 0 and f"no folder {LAB}/ or labs/{LAB}/" in r["output"]
    assert "notes.txt" in r["output"]


def test_grade_all_on_the_real_course_as_nobody(autograder, base, points):
    """Batch regrading with the autograder's environment (readable by the sandbox user), as root with the drop.

    The stubs are not among the submissions: grade-all grades this lab's stubs as the sandbox user in
    test_batch.py (the documented path) and run_autograder grades them in test_stubs_score_zero."""
    subs = base / "subs"
    shutil.copytree(ROOT / "solutions" / LAB, subs / "alice" / "labs" / LAB)
    (subs / "carol").mkdir()
    subprocess.run(["chmod", "-R", "a+rX", str(subs)], check=True)
    out = base / "regrade"
    env = _env(GEOMLIB_ROOT=str(autograder / "source"))
    if not IS_ROOT:
        env["GEOMLIB_SANDBOX_USER"] = ""
    py = autograder / "source" / ".venv" / "bin" / "python"
    cmd = [str(py), "-m", "geomlib.cli", "grade-all", str(subs), "--lab", LAB, "--out", str(out), "--jobs", "2"]
    p = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=900)
    assert p.returncode == 0, p.stdout + p.stderr
    import csv

    rows = {r["submission"]: r for r in csv.DictReader((out / "scores.csv").open())}
    total = sum(p + h for p, h in points.values())
    assert float(rows["alice"]["score"]) == float(rows["(max)"]["score"]) == total and rows["alice"]["status"] == "ok"
    assert rows["carol"]["status"] == "no lab"
    for who in ("alice", "carol"):
        validate_results(json.loads((out / who / "results.json").read_text()))
