"""``geomlib release OUT``: the student bundle and the Gradescope autograder zip.

``OUT/student/`` (and ``OUT/student.zip``)
    geomlib, the stubs in labs/, public graded tests and public references, notebooks without
    outputs, the student README and guide, pyproject.toml, uv.lock, the ``run`` script.
    No solution code, no hidden tests, no hidden references.
``OUT/autograder.zip``
    ``setup.sh`` and ``run_autograder`` at the top (Gradescope's layout) plus the same sources with
    the hidden tests and references. ``run_autograder`` copies the submission's lab folders over the
    stubs, grades them and writes ``results/results.json``.
"""

from __future__ import annotations

import json
import shutil
import stat
import zipfile
from pathlib import Path

from geomlib.grading import impl as _impl
from geomlib.grading import stubs

__all__ = ["release", "student_files", "leaked_lines"]

_SKIP_DIRS = {"__pycache__", ".ipynb_checkpoints", ".pytest_cache", ".ruff_cache"}
_TOP_FILES = ["pyproject.toml", "uv.lock", "run", ".python-version"]

SETUP_SH = """#!/usr/bin/env bash
# Gradescope runs this once when the autograder image is built (as root, Ubuntu).
set -euo pipefail
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq libosmesa6 python3 python3-pip python3-venv curl >/dev/null
command -v uv >/dev/null || python3 -m pip install --quiet uv 2>/dev/null || python3 -m pip install --quiet --break-system-packages uv
cd /autograder/source
uv sync --frozen
# Hidden references stay readable by root only; student code runs as `nobody` (GEOMLIB_SANDBOX_USER).
find tests/reference -type d -name hidden -exec chmod -R go-rwx {} +
"""

RUN_AUTOGRADER = """#!/usr/bin/env bash
# Gradescope calls this for every submission. It never exits before results.json is written.
set -u
ROOT="${GEOMLIB_AUTOGRADER_ROOT:-/autograder}"
SRC="$ROOT/source"
SUB="$ROOT/submission"
RESULTS="$ROOT/results/results.json"
mkdir -p "$ROOT/results"
cd "$SRC" || exit 0

# The submission may be the lab folders themselves or a checkout that contains labs/.
if [ -d "$SUB/labs" ]; then SUBLABS="$SUB/labs"; else SUBLABS="$SUB"; fi
for lab in labs/*/; do
  name=$(basename "$lab")
  if [ -d "$SUBLABS/$name" ]; then
    rm -rf "labs/$name"
    cp -r "$SUBLABS/$name" "labs/$name"
  fi
done
chmod -R a+rX labs

export GEOMLIB_SANDBOX_USER="${GEOMLIB_SANDBOX_USER-nobody}"
export GEOMLIB_NO_FEEDBACK_PICTURES="${GEOMLIB_NO_FEEDBACK_PICTURES-1}"
PY="${GEOMLIB_PYTHON:-uv run --frozen python}"
$PY -m geomlib.cli grade --impl labs --results "$RESULTS" --feedback "$ROOT/results/feedback" > "$ROOT/results/grader-output.txt" 2>&1
status=$?
if [ ! -s "$RESULTS" ]; then
  # The grader itself failed: report it instead of losing the submission's result.
  python3 - "$RESULTS" "$ROOT/results/grader-output.txt" "$status" <<'PY'
import json, sys
out = open(sys.argv[2], errors="replace").read()[-4000:]
json.dump({"score": 0, "output": f"The autograder failed (exit {sys.argv[3]}); please tell the course staff.\\n\\n{out}",
           "tests": []}, open(sys.argv[1], "w"))
PY
fi
cat "$ROOT/results/grader-output.txt"
exit 0
"""


def _is_hidden(rel: Path) -> bool:
    return any("hidden" in part for part in rel.parts)


def student_files(root: Path, *, include_hidden: bool) -> list[tuple[Path, Path]]:
    """(source, relative destination) pairs of everything a student (or the autograder) gets."""
    out: list[tuple[Path, Path]] = []

    def add_tree(folder: str, keep=lambda rel: True):
        base = root / folder
        if not base.is_dir():
            return
        for p in sorted(base.rglob("*")):
            rel = p.relative_to(root)
            if p.is_dir() or _SKIP_DIRS & set(rel.parts) or p.name == "READY":
                continue
            if keep(rel):
                out.append((p, rel))

    add_tree("geomlib")
    add_tree("labs")
    add_tree("notebooks", keep=lambda rel: rel.suffix == ".ipynb" or rel.name == "README.md")
    add_tree(
        "docs",
        keep=lambda rel: rel.name in ("students.md", "cameras.md", "cameras.png") or rel.parts[1:2] == ("figures",),
    )

    def keep_test(rel: Path) -> bool:
        parts = rel.parts
        if parts[1] not in ("graded", "reference", "conftest.py"):
            return False  # library tests, solution cross-checks and framework tests stay with instructors
        return include_hidden or not _is_hidden(rel)

    add_tree("tests", keep=keep_test)
    for name in _TOP_FILES:
        if (root / name).is_file():
            out.append((root / name, Path(name)))
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


def _zip(folder: Path, zip_path: Path) -> None:
    with zipfile.ZipFile(zip_path, "w", zipfile.ZIP_DEFLATED) as z:
        for p in sorted(folder.rglob("*")):
            if p.is_file():
                z.write(p, str(Path(folder.name) / p.relative_to(folder)))


def leaked_lines(bundle: Path, *, min_len: int = 12) -> list[tuple[str, str]]:
    """Distinctive lines from inside solution blocks that appear anywhere in ``bundle``.

    A line counts as distinctive when it is at least ``min_len`` characters long and does not also
    appear outside the solution blocks in ``solutions/`` (given code legitimately shared).
    """
    root = _impl.course_root()
    inside: set[str] = set()
    outside: set[str] = set()
    for f in (p for p in (root / "solutions").rglob("*") if p.suffix in stubs.STUB_SUFFIXES):  # shaders too
        text = f.read_text()
        sol = set(stubs.solution_lines(text, str(f)))
        inside |= sol
        outside |= {ln.strip() for ln in stubs.make_stub(text, str(f)).splitlines()}
    secret = {ln for ln in inside - outside if len(ln) >= min_len and not ln.startswith("#")}
    leaks = []
    for p in bundle.rglob("*"):
        if not p.is_file() or p.suffix in (".npz", ".png", ".zip", ".lock"):
            continue
        try:
            text = p.read_text()
        except (UnicodeDecodeError, OSError):
            continue
        for ln in text.splitlines():
            s = ln.strip()
            if s in secret:
                leaks.append((str(p.relative_to(bundle)), s))
    return leaks


def release(out: Path) -> dict[str, Path]:
    """Write ``out/student/``, ``out/student.zip`` and ``out/autograder.zip``; returns their paths.

    Raises
    ------
    RuntimeError
        When ``labs/`` is stale or a solution line would leak into the student bundle.
    """
    root = _impl.course_root()
    problems = stubs.check()
    if problems:
        raise RuntimeError("labs/ is stale; run `geomlib stubs build` first:\n  " + "\n  ".join(problems))
    out = Path(out)
    student = out / "student"
    if student.exists():
        shutil.rmtree(student)
    _copy(student_files(root, include_hidden=False), student)
    guide = root / "docs" / "students.md"
    if guide.is_file():
        shutil.copy2(guide, student / "README.md")
    leaks = leaked_lines(student)
    if leaks:
        raise RuntimeError(
            "solution lines would leak into the student bundle:\n  " + "\n  ".join(f"{f}: {s}" for f, s in leaks[:10])
        )
    _zip(student, out / "student.zip")

    staging = out / "autograder-source"
    if staging.exists():
        shutil.rmtree(staging)
    _copy(student_files(root, include_hidden=True), staging)
    zpath = out / "autograder.zip"
    with zipfile.ZipFile(zpath, "w", zipfile.ZIP_DEFLATED) as z:
        for name, text in (("setup.sh", SETUP_SH), ("run_autograder", RUN_AUTOGRADER)):
            info = zipfile.ZipInfo(name)
            info.external_attr = (0o755 | stat.S_IFREG) << 16
            z.writestr(info, text)
        for p in sorted(staging.rglob("*")):
            if p.is_file():
                z.write(p, str(p.relative_to(staging)))
    shutil.rmtree(staging)
    return {"student": student, "student_zip": out / "student.zip", "autograder_zip": zpath}
