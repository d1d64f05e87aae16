"""``geomlib release OUT [--lab NAME ...]``: the student bundle and one Gradescope autograder zip per lab.

``OUT/student/`` (and ``OUT/student.zip``)
    geomlib, the stubs of the chosen labs, their public graded tests and public references,
    notebooks without outputs, the student guide as README.md, pyproject.toml, uv.lock, ``run``,
    the dev container (``.devcontainer/``).
    No solution code, no hidden tests, no hidden references, no other lab.
``OUT/autograder-<lab>.zip``, one per chosen lab
    Gradescope's layout: ``setup.sh`` and ``run_autograder`` at the top, next to the sources that
    grade that lab only (its stubs, public and hidden tests and references, geomlib, the lock).
    Both scripts honour ``GEOMLIB_AUTOGRADER_ROOT`` (default ``/autograder``: ``source/``,
    ``submission/``, ``results/`` under it), so the zip installs and runs locally too
    (``docs/autograder.md``).

Everything is written into a temporary folder inside ``OUT`` and moved into place only when the
whole release succeeded: a failed release leaves ``OUT`` as it was.
"""

from __future__ import annotations

import json
import os
import shutil
import stat
import subprocess
import tempfile
import time
import zipfile
from pathlib import Path

from geomlib.grading import impl as _impl
from geomlib.grading import stubs
from geomlib.grading.course import course

__all__ = [
    "release",
    "check_solutions",
    "student_files",
    "autograder_files",
    "leaked_lines",
    "secret_lines",
    "ReleaseError",
]

_SKIP_DIRS = {"__pycache__", ".ipynb_checkpoints", ".pytest_cache", ".ruff_cache"}
_TOP_FILES = ["pyproject.toml", "uv.lock", "run", ".python-version", ".dockerignore"]
_TEXT_SUFFIXES = {
    ".py",
    ".frag",
    ".vert",
    ".glsl",
    ".md",
    ".ipynb",
    ".txt",
    ".toml",
    ".json",
    ".cfg",
    ".sh",
    ".yml",
    ".yaml",
    ".rst",
    "",
}


class ReleaseError(RuntimeError):
    """The release cannot be made (stale stubs, missing references, a leak, an unknown lab)."""


# ------------------------------------------------------------------------------------ scripts

#: The one set-up script of a grading machine (Gradescope's image and the dev container's image):
#: ``geomlib/grading/setup.sh``, shipped with the lab's name in place of ``@LAB@``.
SETUP_SH = (Path(__file__).with_name("setup.sh")).read_text()

RUN_AUTOGRADER = r"""#!/usr/bin/env bash
# Gradescope runs this for every submission, as root. It always writes results/results.json.
# Locally (as root):  GEOMLIB_AUTOGRADER_ROOT=/tmp/ag bash /tmp/ag/source/run_autograder
# Grades lab @LAB@ of the submission in $ROOT/submission (a folder holding @LAB@/ or labs/@LAB@/),
# from a private copy (regular files only: symbolic links are not followed), as the sandbox user.
set -u
LAB="@LAB@"
ROOT="${GEOMLIB_AUTOGRADER_ROOT:-/autograder}"
SRC="$ROOT/source"
SUB="$ROOT/submission"
OUT="$ROOT/results"
RESULTS="$OUT/results.json"
LOG="$OUT/grader-output.txt"
PY="${GEOMLIB_PYTHON:-$SRC/.venv/bin/python}"
export GEOMLIB_ROOT="$SRC"
export PATH="$PATH:/usr/sbin:/sbin"  # runuser lives in sbin, which a minimal PATH leaves out
export GEOMLIB_SANDBOX_USER="${GEOMLIB_SANDBOX_USER-nobody}"
# Feedback pictures (inlined into results.json): the first few failures get one each.
export GEOMLIB_MAX_FEEDBACK_PICTURES="${GEOMLIB_MAX_FEEDBACK_PICTURES-8}"
mkdir -p "$OUT"
rm -f "$RESULTS"
: > "$LOG"

grader_failed() {
  # The grader's own failure, never the student's: a results.json that says so (plain bash: the
  # grader's Python may be what is broken).
  printf '{"score": 0, "output": "The autograder itself failed (%s). This is not a problem with your submission: please tell the course staff.", "output_format": "text", "visibility": "visible", "stdout_visibility": "hidden", "tests": []}\n' "$1" > "$RESULTS"
  echo "run_autograder: grader failure: $1" | tee -a "$LOG"
  exit 0
}

cd "$SRC" 2>/dev/null || grader_failed "no source folder at $SRC"
# Whether the grader's Python starts is asked once a step has failed, before its failure is reported:
# a grade imports the same (about 1 s of CPU), so asking first cost every submission that second.
python_starts() {
  "$PY" -c 'import geomlib.grading.grade' >>"$LOG" 2>&1 || grader_failed "its Python environment does not start; run setup.sh"
}
if [ "$(id -u)" = 0 ] && [ -n "$GEOMLIB_SANDBOX_USER" ]; then
  id "$GEOMLIB_SANDBOX_USER" >/dev/null 2>&1 || { python_starts; grader_failed "unknown sandbox user $GEOMLIB_SANDBOX_USER"; }
  (cd / && runuser -u "$GEOMLIB_SANDBOX_USER" -- "$PY" -c 'import numpy, geomlib.grading.worker') >>"$LOG" 2>&1 \
    || { python_starts; grader_failed "the sandbox user $GEOMLIB_SANDBOX_USER cannot run the grader's Python; run setup.sh"; }
fi

WORK="$(mktemp -d "${TMPDIR:-/tmp}/geomlib-submission.XXXXXX")" || { python_starts; grader_failed "cannot create a work folder"; }
trap 'rm -rf "$WORK"' EXIT
chmod 755 "$WORK"
"$PY" -m geomlib.grading.submission "$SUB" "$LAB" "$WORK/labs" --results "$RESULTS" >>"$LOG" 2>&1
status=$?
[ "$status" = 0 ] || python_starts  # a submission without the lab (3), or the Python does not start
if [ "$status" = 0 ]; then
  "$PY" -m geomlib.cli grade --impl "$WORK/labs" --lab "$LAB" --results "$RESULTS" --feedback "$OUT/feedback" >>"$LOG" 2>&1
  status=$?
fi
if [ ! -s "$RESULTS" ]; then
  python_starts
  "$PY" - "$RESULTS" "$LOG" "$status" <<'PY' || grader_failed "it ended with status $status"
import json, sys
out = open(sys.argv[2], errors="replace").read()[-4000:]
msg = f"The autograder itself failed (exit status {sys.argv[3]}). This is not a problem with your submission: please tell the course staff."
json.dump({"score": 0, "output": msg, "output_format": "text", "visibility": "visible",
           "stdout_visibility": "hidden", "tests": []}, open(sys.argv[1], "w"))
print(out)
PY
fi
cat "$LOG"
exit 0
"""

_AUTOGRADER_README = """# Autograder for the lab "{lab}"

Generated by `geomlib release`; see the course's docs/autograder.md. Gradescope unzips this into
/autograder/source, runs `setup.sh` once and `run_autograder` for every submission.
"""


# ------------------------------------------------------------------------------------ files


def _labs(root: Path, labs: list[str] | None) -> list[str]:
    c = course(root)
    known = [n for n in c.labs if n in c.solution_labs]
    if not labs:
        return known
    unknown = [n for n in labs if n not in known]
    if unknown:
        raise ReleaseError(f"unknown lab(s) {', '.join(unknown)}; known: {', '.join(known)}")
    return list(dict.fromkeys(labs))


def _tree(root: Path, base: Path, keep=lambda rel: True, *, deep: bool = True) -> list[tuple[Path, Path]]:
    """(file, path relative to ``root``) under ``base`` that ``keep`` accepts (``deep=False``: its own files only)."""
    out = []
    if not base.is_dir():
        return out
    for p in sorted(base.rglob("*") if deep else base.iterdir()):
        rel = p.relative_to(root)
        if p.is_dir() or p.is_symlink() or _SKIP_DIRS & set(rel.parts) or p.name == "READY":
            continue
        if keep(rel):
            out.append((p, rel))
    return out


def _tests(root: Path, labs: list[str], *, include_hidden: bool) -> list[tuple[Path, Path]]:
    """The graded tests and references of ``labs``, with what they share (the tests' and the graded
    package's own files); library tests, solution cross-checks and framework tests stay with instructors."""
    c = course(root)
    out = _tree(root, c.tests_dir, lambda rel: rel.name == "conftest.py", deep=False)
    out += _tree(root, c.graded_dir, deep=False)  # tests/graded/__init__.py, common.py

    def keep(rel: Path) -> bool:
        return include_hidden or not c.is_hidden(rel)

    for lab in labs:
        paths = c.lab(lab)
        mutants = paths.mutants.relative_to(root)  # `geomlib audit`'s declarations quote solution code
        out += _tree(root, paths.graded, lambda rel, m=mutants: rel != m and keep(rel))
        out += _tree(root, paths.references, keep)
    return out


def student_files(
    root: Path, labs: list[str] | None = None, *, include_hidden: bool = False
) -> list[tuple[Path, Path]]:
    """(source, relative destination) pairs of everything a student gets for ``labs`` (default: all)."""
    c = course(root)
    labs = labs or c.labs
    out = _tree(root, c.library_dir)
    for lab in labs:
        out += _tree(root, c.lab(lab).stubs)
        out += _tree(root, c.lab(lab).docs_figures)
    notebooks = {c.lab(lab).notebook for lab in labs}
    out += _tree(root, c.notebooks_dir, lambda rel: rel.name == "README.md" or root / rel in notebooks, deep=False)
    out += _tree(root, c.docs_dir, lambda rel: rel.name in ("students.md", "cameras.md", "cameras.png"), deep=False)
    out += _tests(root, labs, include_hidden=include_hidden)
    # the dev container (docs/students.md), built by geomlib/grading/setup.sh
    out += _tree(root, root / ".devcontainer")
    out += [(root / n, Path(n)) for n in _TOP_FILES if (root / n).is_file()]
    return out


def autograder_files(root: Path, lab: str) -> list[tuple[Path, Path]]:
    """(source, relative destination) pairs of the sources that grade ``lab`` (hidden material included)."""
    c = course(root)
    out = _tree(root, c.library_dir)
    out += _tree(root, c.lab(lab).stubs, lambda rel: rel.suffix == ".py")
    out += _tests(root, [lab], include_hidden=True)
    out += [(root / n, Path(n)) for n in ("pyproject.toml", "uv.lock", ".python-version") if (root / n).is_file()]
    return out


def _copy(pairs, dest: Path) -> None:
    for src, rel in pairs:
        target = dest / rel
        target.parent.mkdir(parents=True, exist_ok=True)
        if rel.suffix == ".ipynb":
            target.write_text(_strip_outputs(src.read_text()))
        else:
            shutil.copy2(src, target)


def _strip_outputs(text: str) -> str:
    nb = json.loads(text)
    for cell in nb.get("cells", []):
        if cell.get("cell_type") == "code":
            cell["outputs"] = []
            cell["execution_count"] = None
    return json.dumps(nb, indent=1, ensure_ascii=False) + "\n"


def _zip_tree(z: zipfile.ZipFile, folder: Path, prefix: str = "") -> None:
    for p in sorted(folder.rglob("*")):
        if p.is_file():
            rel = p.relative_to(folder).as_posix()
            info = zipfile.ZipInfo(prefix + rel, date_time=(2000, 1, 1, 0, 0, 0))
            mode = 0o755 if os.access(p, os.X_OK) else 0o644
            info.external_attr = (mode | stat.S_IFREG) << 16
            info.compress_type = zipfile.ZIP_DEFLATED
            z.writestr(info, p.read_bytes())


def _script(z: zipfile.ZipFile, name: str, text: str) -> None:
    info = zipfile.ZipInfo(name, date_time=(2000, 1, 1, 0, 0, 0))
    info.external_attr = (0o755 | stat.S_IFREG) << 16
    info.compress_type = zipfile.ZIP_DEFLATED
    z.writestr(info, text)


# ------------------------------------------------------------------------------------ leaks


def _baseline_lines(root: Path) -> set[str]:
    """Stripped lines of the code that ships anyway: the library and the given code of every stub."""
    lines: set[str] = set()
    c = course(root)
    for f in c.library_dir.rglob("*.py"):
        if "__pycache__" not in f.parts:
            lines |= {ln.strip() for ln in f.read_text().splitlines()}
    for f in c.solutions_dir.rglob("*"):
        if f.suffix in stubs.STUB_SUFFIXES and "__pycache__" not in f.parts:  # shaders too
            lines |= {ln.strip() for ln in stubs.make_stub(f.read_text(), str(f)).splitlines()}
    return lines


def secret_lines(root: Path | None = None, labs: list[str] | None = None) -> dict[str, set[str]]:
    """``{task: lines}``: the lines inside each solution block that appear nowhere in the code that ships anyway.

    The code that ships anyway is the library (``geomlib/``) and the stubs' given code; a line of a
    solution block found there (``return False``, ``if tol is None:``) gives nothing away. Comments
    are not code and do not count. Tasks are named ``<lab>/<file>: <task as the BEGIN marker names it>``.
    """
    root = Path(root) if root else _impl.course_root()
    baseline = _baseline_lines(root)
    out: dict[str, set[str]] = {}
    solutions = course(root).solutions_dir
    for f in sorted(p for p in solutions.rglob("*") if p.suffix in stubs.STUB_SUFFIXES):
        if "__pycache__" in f.parts or (labs and f.relative_to(solutions).parts[0] not in labs):
            continue
        rel = f.relative_to(solutions).as_posix()
        for task, body in stubs.solution_blocks(f.read_text(), str(f)):
            secret = {ln for ln in body if not ln.startswith(("#", "//")) and ln not in baseline}
            if secret:
                key = f"{rel}: {task}"
                out.setdefault(key, set()).update(secret)
    return out


def leaked_lines(bundle: Path, secrets: dict[str, set[str]] | None = None) -> list[tuple[str, str, str]]:
    """``(file, line, task)`` for every line of a text file under ``bundle`` that is a solution's secret line."""
    secrets = secret_lines() if secrets is None else secrets
    owner = {ln: task for task, lines in secrets.items() for ln in lines}
    leaks = []
    for p in sorted(Path(bundle).rglob("*")):
        if not p.is_file() or p.suffix not in _TEXT_SUFFIXES:
            continue
        try:
            text = p.read_text()
        except (UnicodeDecodeError, OSError):
            continue
        if p.suffix == ".ipynb":  # notebook source is JSON: look at the cells' own lines
            try:
                cells = json.loads(text).get("cells", [])
                text = "\n".join("".join(c.get("source", [])) for c in cells)
            except (ValueError, AttributeError):
                pass
        for ln in text.splitlines():
            s = ln.strip()
            if s in owner:
                leaks.append((p.relative_to(bundle).as_posix(), s, owner[s]))
    return leaks


# ------------------------------------------------------------------------------------ release


def _check_course(root: Path, labs: list[str]) -> None:
    problems = stubs.check(labs)
    if problems:
        raise ReleaseError(f"labs/ is stale ({problems[0]}); run `geomlib stubs build` first")
    from geomlib.grading.cases import load_cases, reference_path

    for lab in labs:
        missing = [c.id for c in load_cases(lab) if not reference_path(lab, c).is_file()]
        if missing:
            raise ReleaseError(
                f"{lab}: {len(missing)} reference output(s) missing (e.g. {missing[0]}); "
                f"run `geomlib refs build --lab {lab}` first"
            )


def check_solutions(labs: list[str], *, log=print) -> None:
    """Grade the solutions of each lab on its graded tests, public and hidden, through the sandbox
    (:func:`geomlib.grading.refs.graded_failures`); raise :class:`ReleaseError` naming the failing
    tests of every lab whose solutions do not score full marks (as ``otter assign`` refuses an
    assignment whose solution fails its tests). A rebuilt reference follows a changed solution, a
    hand-written test does not: this is where a broken solution shows."""
    from geomlib.grading import refs

    broken = []
    for lab in labs:
        t = time.time()
        try:
            score, out_of, failures = refs.graded_failures(lab)
        except (RuntimeError, OSError, subprocess.SubprocessError) as e:
            raise ReleaseError(f"{lab}: the solutions could not be graded: {e}") from None
        log(f"  {lab}: the solutions score {score:g} / {out_of:g} (public and hidden tests, {time.time() - t:.0f} s)")
        if failures:
            lines = [f"    {name}: {msg}" for name, msg in failures[:12]]
            if len(failures) > 12:
                lines.append(f"    … and {len(failures) - 12} more")
            broken.append(
                f"{lab}: the solutions score {score:g} / {out_of:g} on their own tests; "
                f"{len(failures)} test(s) fail:\n" + "\n".join(lines)
            )
    if broken:
        raise ReleaseError(
            "a release would ship a broken solution\n"
            + "\n".join(broken)
            + "\nfix the solution (or the test), then `geomlib refs check --lab LAB` lists what still fails"
        )


def release(out: str | os.PathLike, labs: list[str] | None = None, *, check: bool = True, log=print) -> dict[str, Path]:
    """Write the student bundle and one autograder zip per lab into ``out``; returns their paths.

    Parameters
    ----------
    out : path
        Output folder (created if needed). Earlier outputs of the same names are replaced.
    labs : list of str, optional
        Labs to release (default: every lab with a solution).
    check : bool
        Grade the solutions of each lab first (:func:`check_solutions`; ``geomlib release --no-check``
        skips it, for packaging only).

    Raises
    ------
    ReleaseError
        When a lab is unknown, ``labs/`` is stale, references are missing, the solutions fail a
        graded test or a solution line would reach students. ``out`` is then left as it was.
    """
    root = _impl.course_root()
    labs = _labs(root, labs)
    _check_course(root, labs)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=".release-", dir=out))
    try:
        student = tmp / "student"
        _copy(student_files(root, labs), student)
        guide = course(root).docs_dir / "students.md"
        if guide.is_file():
            shutil.copy2(guide, student / "README.md")
        leaks = leaked_lines(student)
        if leaks:
            f, line, task = leaks[0]
            raise ReleaseError(
                f"{len(leaks)} solution line(s) would reach students, e.g. {f}: {line!r} (from {task}); "
                f"move that code into a solution block's stored reference or the library"
            )
        if check:  # the slowest check last: after the quick ones, before anything is in place
            check_solutions(labs, log=log)
        with zipfile.ZipFile(tmp / "student.zip", "w") as z:
            _zip_tree(z, student, "student/")
        made = {"student": out / "student", "student_zip": out / "student.zip"}
        for lab in labs:
            staging = tmp / f"source-{lab}"
            _copy(autograder_files(root, lab), staging)
            (staging / "README.md").write_text(_AUTOGRADER_README.format(lab=lab))
            name = f"autograder-{lab}.zip"
            with zipfile.ZipFile(tmp / name, "w") as z:
                _script(z, "setup.sh", SETUP_SH.replace("@LAB@", lab))
                _script(z, "run_autograder", RUN_AUTOGRADER.replace("@LAB@", lab))
                _zip_tree(z, staging)
            shutil.rmtree(staging)
            made[f"autograder_{lab}"] = out / name
        # Everything is ready: move it into place (replacing earlier outputs of the same names).
        for path in made.values():
            if path.is_dir() and not path.is_symlink():
                shutil.rmtree(path)
            elif path.exists() or path.is_symlink():
                path.unlink()
            (tmp / path.name).rename(path)
        for path in made.values():
            log(f"  {path}")
        return made
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
