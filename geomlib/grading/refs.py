"""Reference outputs: built from the solutions by ``geomlib refs build``, verified by ``geomlib refs check``.

Layout::

    tests/reference/<lab>/<case>.npz            public cases (named arrays)
    tests/reference/<lab>/manifest.json          parameters, input digests, versions, checksums
    tests/reference/<lab>/hidden/<case>.npz     hidden cases (never shipped to students)
    tests/reference/<lab>/hidden/manifest.json

Never edit these files by hand: change the solution or the case, then rebuild.
"""

from __future__ import annotations

import hashlib
import io
import json
import os
import platform
import re
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from geomlib.grading import impl as _impl
from geomlib.grading.cases import Case, inputs_digest, load_cases, load_stored, reference_path, stored_path
from geomlib.grading.checks import Context
from geomlib.grading.course import course
from geomlib.grading.errors import GradingFailure
from geomlib.grading.stubs import Written

__all__ = ["build", "check", "graded_failures", "RefProblem"]


@dataclass
class RefProblem:
    lab: str
    case: str
    message: str


def _versions() -> dict:
    import scipy

    out = {"python": platform.python_version(), "numpy": np.__version__, "scipy": scipy.__version__}
    try:
        import igl

        out["libigl"] = getattr(igl, "__version__", "?")
    except ImportError:
        pass
    return out


def _to_arrays(case: Case, result) -> dict[str, np.ndarray]:
    named = case.name_outputs(result)
    out = {}
    for k, v in named.items():
        if hasattr(v, "toarray"):  # sparse matrix outputs are stored dense only if small
            v = v.toarray()
        a = np.asarray(v)
        if a.dtype == object:
            raise TypeError(f"case {case.id}: output {k} is not a numeric array")
        out[k] = a
    return out


def _npz_bytes(arrays: dict[str, np.ndarray]) -> bytes:
    """A compressed ``.npz`` whose bytes depend on the arrays only (no time stamps): a rebuild that
    reproduces the outputs leaves the files, and git, unchanged."""
    import zipfile

    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as z:
        for name, a in arrays.items():
            info = zipfile.ZipInfo(f"{name}.npy", date_time=(1980, 1, 1, 0, 0, 0))
            info.compress_type = zipfile.ZIP_DEFLATED
            with z.open(info, "w", force_zip64=True) as f:
                np.lib.format.write_array(f, np.asanyarray(a), allow_pickle=False)
    return buf.getvalue()


def _holds(path: Path, arrays: dict[str, np.ndarray]) -> bool:
    """Whether the ``.npz`` at ``path`` holds exactly ``arrays`` (names, dtypes, shapes and bytes).

    Its bytes may differ all the same: zipfile's headers for ``force_zip64`` differ between Python
    patch releases (3.11.2 writes the sizes, 3.11.7 0xffffffff and a zip64 record), so a course set up
    with another Python would otherwise rewrite, and list, every reference."""
    try:
        with np.load(path, allow_pickle=False) as z:
            if sorted(z.files) != sorted(arrays):
                return False
            for k, a in arrays.items():
                b = z[k]
                if b.dtype != a.dtype or b.shape != a.shape or b.tobytes() != np.ascontiguousarray(a).tobytes():
                    return False
        return True
    except Exception:  # unreadable or not an npz: write it again
        return False


def _run_solution(lab: str, case: Case) -> tuple[dict, str]:
    mod = _impl.load_lab(lab, course().solutions_dir.name)
    fn = getattr(mod, case.function)
    inputs = case.inputs()
    digest = inputs_digest(inputs, case.params)
    return _to_arrays(case, fn(**inputs, **case.params)), digest


def _entry(case: Case, digest: str, arrays: dict) -> dict:
    return {
        "function": case.function,
        "params": case.params,
        "part": case.part,
        "points": case.points,
        "visibility": case.visibility,
        "inputs_sha256": digest,
        "outputs": {
            k: {
                "shape": list(a.shape),
                "dtype": str(a.dtype),
                "sha256": hashlib.sha256(np.ascontiguousarray(a).tobytes()).hexdigest(),
            }
            for k, a in arrays.items()
        },
    }


def _write_manifests(lab: str, manifests: dict, folders: dict, note: str) -> Written:
    """Write the manifests that changed; returns them (the others counted in ``unchanged``)."""
    written = Written()
    for key, entries in manifests.items():
        folder = folders[key]
        if not entries:
            continue
        for old in folder.glob("*.npz"):  # drop stale files of cases that no longer exist
            if old.stem not in entries:
                old.unlink()
        manifest = {
            "generated_by": f"geomlib refs build --lab {lab}",
            "note": note,
            "versions": _versions(),
            "cases": entries,
        }
        text = json.dumps(manifest, indent=1, sort_keys=True) + "\n"
        path = folder / "manifest.json"
        if not _same_manifest(path, manifest):
            path.write_text(text)
            written.append(path)
        else:
            written.unchanged += 1
    return written


def _same_manifest(path: Path, manifest: dict) -> bool:
    """Whether ``path`` holds ``manifest`` but for ``versions``: the versions record who built the files,
    and a rebuild that reproduces every file under another patch release of Python (or NumPy) changes
    nothing worth a new manifest."""
    try:
        old = json.loads(path.read_text())
    except (OSError, ValueError):
        return False
    return {k: v for k, v in old.items() if k != "versions"} == {k: v for k, v in manifest.items() if k != "versions"}


def _build_outputs(lab: str, cases, path_of, folders: dict, note: str, log) -> Written:
    """Run the solution on each case, write one ``.npz`` per case at ``path_of(lab, case)`` and the
    public/hidden manifests into ``folders``; return the files written. A file that already holds the
    same bytes is left untouched (counted in ``unchanged``), so only what changed is listed."""
    ref = _impl.reference_dir()
    written = Written()
    manifests = {False: {}, True: {}}
    for case in cases:
        arrays, digest = _run_solution(lab, case)
        path = path_of(lab, case)
        path.parent.mkdir(parents=True, exist_ok=True)
        data = _npz_bytes(arrays)
        manifests[case.hidden][case.id] = _entry(case, digest, arrays)
        if path.is_file() and (path.read_bytes() == data or _holds(path, arrays)):
            written.unchanged += 1
            continue
        path.write_bytes(data)
        written.append(path)
        log(f"  {path.relative_to(ref)}  {', '.join(f'{k}{list(a.shape)}' for k, a in arrays.items())}")
    manifest_files = _write_manifests(lab, manifests, folders, note)
    for path in manifest_files:
        written.append(path)
        log(f"  {path.relative_to(ref)}")
    written.unchanged += manifest_files.unchanged
    return written


def build(labs: list[str] | None = None, *, log=print) -> Written:
    """Run the solutions on every stored input and every declared case and store the outputs.

    Stored inputs (``STORED``) are built first, in order, since cases' inputs may read them.
    Returns the files written (those whose content changed), listed through ``log``; the number
    of files left unchanged is its ``unchanged`` attribute.
    """
    labs = labs or _impl.lab_names()
    written = Written()
    for lab in labs:
        paths = course().lab(lab)
        stored = load_stored(lab)
        parts = []
        if stored:  # before the cases, whose inputs may read them
            folders = {False: paths.stored_inputs, True: paths.hidden_stored_inputs}
            note = "inputs of graded tests, from solutions/; do not edit by hand"
            parts.append(_build_outputs(lab, stored, stored_path, folders, note, log))
        cases = load_cases(lab)
        if cases:
            folders = {False: paths.references, True: paths.hidden_references}
            note = "generated from solutions/; do not edit by hand"
            parts.append(_build_outputs(lab, cases, reference_path, folders, note, log))
        for part in parts:
            written += part
            written.unchanged += part.unchanged
    return written


def graded_failures(lab: str, *, timeout: float = 3600) -> tuple[float, float, list[tuple[str, str]]]:
    """Grade the solutions of ``lab`` on its graded tests, public and hidden, through the sandbox, as
    ``geomlib grade --impl solutions --lab LAB`` does (in a fresh process: a grading session imports
    the lab's test modules, which must not linger in the caller).

    Returns
    -------
    score, max_score : float
    failures : list of (test, message)
        The tests that do not pass (named as in the score table, without the lab), with the first
        line of their message.
    """
    root = _impl.course_root()
    env = {**os.environ, "GEOMLIB_ROOT": str(root), "GEOMLIB_NO_FEEDBACK_PICTURES": "1"}
    env.pop("GEOMLIB_IMPL", None)
    # This asks whether the solutions are right, not whether this machine is fast: a busy build
    # machine must not turn a correct solution into a refused release. Per-call limits stay as a
    # guard against hangs (300 s, far above any solution's need) and the whole-run budget is off.
    env.setdefault("GEOMLIB_TIME_LIMIT", "300")
    env.setdefault("GEOMLIB_TIME_BUDGET", "0")
    with tempfile.TemporaryDirectory(prefix="geomlib-solutions-") as tmp:
        results = Path(tmp) / "results.json"
        cmd = [sys.executable, "-m", "geomlib.cli", "grade", "--impl", course().solutions_dir.name, "--lab", lab]
        cmd += ["--results", str(results), "--feedback", str(Path(tmp) / "feedback")]
        p = subprocess.run(cmd, cwd=root, env=env, capture_output=True, text=True, timeout=timeout)
        if p.returncode != 0 or not results.is_file():
            tail = (p.stdout + p.stderr).strip().splitlines()[-12:]
            raise RuntimeError(f"grading the solutions of {lab} failed (exit {p.returncode}):\n" + "\n".join(tail))
        data = json.loads(results.read_text())
    tests = data.get("tests", [])
    failures = []
    for t in tests:
        if t.get("status") != "passed" or t.get("score", 0) < t.get("max_score", 0):
            name = t["name"].removeprefix(f"{lab} › ")
            message = re.sub(r"\\([\\`*_{}\[\]()#+\-.!|<>])", r"\1", (t.get("output") or "failed").strip())
            message = message.splitlines()[0]  # the results' Markdown escapes undone: read in a terminal
            failures.append((name, message[:240] + ("…" if len(message) > 240 else "")))
    if not tests:
        failures.append(("(no test)", data.get("output", "no graded test ran")[:240]))
    return float(data.get("score", 0.0)), float(sum(t.get("max_score", 0.0) for t in tests)), failures


def check(labs: list[str] | None = None, *, grade: bool = True, outputs: bool = True, log=print) -> list[RefProblem]:
    """Re-run the solutions and compare with the stored references using each case's own check;
    with ``grade``, also grade the solutions on every graded test (:func:`graded_failures`) and
    report each test they fail (hand-written tests hold expected values no reference rebuild moves).

    Without ``outputs`` the cases' functions are not re-run (their inputs are still digested and
    the stored inputs still rebuilt and compared): for a run whose graded tests already compare the
    solutions' outputs with every reference, public and hidden (the test suite), so each case runs once."""
    labs = labs or _impl.lab_names()
    problems: list[RefProblem] = []
    for lab in labs:
        inputs = load_stored(lab)
        cases = load_cases(lab)
        for case in inputs + cases:
            path = stored_path(lab, case) if any(case is c for c in inputs) else reference_path(lab, case)
            if not path.is_file():
                problems.append(RefProblem(lab, case.id, f"missing {path.name}: run `geomlib refs build --lab {lab}`"))
                continue
            manifest_path = path.parent / "manifest.json"
            manifest = json.loads(manifest_path.read_text()) if manifest_path.is_file() else {"cases": {}}
            entry = manifest["cases"].get(case.id)
            rerun = outputs or any(case is c for c in inputs)
            if rerun:
                arrays, digest = _run_solution(lab, case)
            else:
                digest = inputs_digest(case.inputs(), case.params)
            if entry is None:
                problems.append(RefProblem(lab, case.id, "not in the manifest: rebuild the references"))
            elif entry["inputs_sha256"] != digest or entry["params"] != case.params:
                problems.append(
                    RefProblem(lab, case.id, "the case's inputs or parameters changed since the references were built")
                )
                continue
            if not rerun:
                continue
            with np.load(path, allow_pickle=False) as z:
                stored = {k: z[k] for k in z.files}
            # Worded for the solution (not "submitted"); the case is named once, by the report line.
            ctx = Context(label=case.id, lab=lab, case_id=case.id, got_name="recomputed", got_owner="the solution")
            try:
                case.check(stored, arrays, ctx)
            except GradingFailure as e:
                what = str(e).removeprefix(f"{ctx.label}: ")
                problems.append(RefProblem(lab, case.id, f"the solution no longer reproduces the reference: {what}"))
        # Reference files for which no case exists any more.
        known = {(c.hidden, c.id) for c in cases}
        known_inputs = {(c.hidden, c.id) for c in inputs}
        for hidden in (False, True):
            paths = course().lab(lab)
            folder = paths.hidden_references if hidden else paths.references
            for f in folder.glob("*.npz"):
                if (hidden, f.stem) not in known:
                    problems.append(RefProblem(lab, f.stem, f"stale reference file {f.name} has no case"))
            for f in (paths.hidden_stored_inputs if hidden else paths.stored_inputs).glob("*.npz"):
                if (hidden, f.stem) not in known_inputs:
                    problems.append(RefProblem(lab, f.stem, f"stale stored input {f.name} has no STORED entry"))
        log(
            f"  {lab}: {len(inputs)} stored inputs and {len(cases)} cases checked"
            + ("" if outputs else " (not re-run)")
        )
        if grade:
            score, out_of, failures = graded_failures(lab)
            problems += [RefProblem(lab, name, f"the solution fails this graded test: {msg}") for name, msg in failures]
            log(f"  {lab}: the solutions score {score:g} / {out_of:g} on the graded tests (public and hidden)")
    return problems
