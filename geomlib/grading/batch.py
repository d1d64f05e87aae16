"""``geomlib grade-all SUBMISSIONS_DIR --lab NAME --out DIR``: grade many submissions of one lab.

``SUBMISSIONS_DIR`` is either a folder per student (any names) or Gradescope's "Export
Submissions" download unzipped: ``submission_metadata.yml`` plus one ``submission_<id>/`` folder
per submission (the metadata gives the students' names, ids and e-mails). Each submission is found
(``<lab>/`` or ``labs/<lab>/``), copied without following links into a private temporary folder and
graded by ``geomlib grade`` in its own process, several at once (``--jobs``). A submission that
crashes, hangs past ``--timeout`` or holds no lab costs only its own row.

Writes ``DIR/<submission>/results.json`` (and ``grader-output.txt``) per submission and
``DIR/scores.csv``: a row per submission, a column per part (public and hidden points together).
"""

from __future__ import annotations

import contextlib
import csv
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor, as_completed
from dataclasses import dataclass, field
from pathlib import Path

from geomlib.grading.submission import SubmissionError, copy_lab, find_lab

__all__ = ["grade_all", "discover", "Submission", "BatchError"]


class BatchError(ValueError):
    """The submissions folder or the lab cannot be graded at all."""


@dataclass
class Submission:
    id: str
    folder: Path
    names: list[str] = field(default_factory=list)
    sids: list[str] = field(default_factory=list)
    emails: list[str] = field(default_factory=list)


def _unquote(v: str) -> str:
    v = v.strip()
    if len(v) >= 2 and v[0] == v[-1] and v[0] in "'\"":
        v = v[1:-1]
    return v


def _read_metadata(path: Path) -> dict[str, dict[str, list[str]]]:
    """The submitters of each submission in Gradescope's ``submission_metadata.yml``.

    Only the fields needed here are read (``:name:``, ``:sid:``, ``:email:`` under
    ``:submitters:``), with a line parser, so no YAML library is needed.
    """
    out: dict[str, dict[str, list[str]]] = {}
    current = None
    in_submitters = False
    for line in path.read_text(errors="replace").splitlines():
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        top = re.match(r"^([^\s:#][^:]*):\s*$", line)
        if top:
            current = out.setdefault(top.group(1).strip(), {"name": [], "sid": [], "email": []})
            in_submitters = False
            continue
        if current is None:
            continue
        m = re.match(r"^(\s*)(?:-\s+)?:(\w+):\s*(.*)$", line)
        if not m:
            continue
        indent, key, value = len(m.group(1)), m.group(2), m.group(3)
        if key == "submitters":
            in_submitters = True
            continue
        if indent <= 2 and "- " not in line[: indent + 2]:
            in_submitters = key == "submitters"
        if in_submitters and key in ("name", "sid", "email"):
            current[key].append(_unquote(value))
    return out


def discover(submissions: Path) -> list[Submission]:
    """The submissions in a folder: Gradescope's export layout, else one sub-folder per student."""
    submissions = Path(submissions)
    if not submissions.is_dir():
        raise BatchError(f"submissions folder {submissions} does not exist")
    meta = submissions / "submission_metadata.yml"
    found: list[Submission] = []
    if meta.is_file():
        for key, who in _read_metadata(meta).items():
            folder = submissions / key
            found.append(Submission(key, folder, who["name"], who["sid"], who["email"]))
        return found
    for p in sorted(submissions.iterdir()):
        if p.is_dir() and not p.is_symlink() and not p.name.startswith((".", "_")):
            found.append(Submission(p.name, p))
    if not found:
        raise BatchError(f"{submissions} holds no submission folders (nor a submission_metadata.yml)")
    return found


def _safe(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.@-]+", "_", name).strip("._") or "submission"


def _failure(message: str) -> dict:
    return {
        "score": 0,
        "output": message,
        "output_format": "text",
        "visibility": "visible",
        "stdout_visibility": "hidden",
        "tests": [],
    }


def sandbox_user() -> str:
    """The user student code runs as: ``GEOMLIB_SANDBOX_USER``, else ``nobody`` when root, else none."""
    default = "nobody" if os.geteuid() == 0 else ""
    return os.environ.get("GEOMLIB_SANDBOX_USER", default)


def check_sandbox_user(user: str) -> None:
    """Fail clearly unless ``user`` can run this Python and import the grader's worker.

    A Python the sandbox user cannot read (one installed under ``/root``, say) would otherwise make
    student code fail on its first import, and the message would blame the student.
    """
    if not user or os.geteuid() != 0:
        return
    try:
        p = subprocess.run(
            ["runuser", "-u", user, "--", sys.executable, "-c", "import numpy, geomlib.grading.worker"],
            cwd="/", capture_output=True, text=True, timeout=120,
        )  # fmt: skip
        ok, why = p.returncode == 0, (p.stderr.strip().splitlines() or ["?"])[-1]
    except (OSError, subprocess.TimeoutExpired) as e:
        ok, why = False, str(e)
    if not ok:
        raise BatchError(
            f"the sandbox user {user!r} cannot run {sys.executable} ({why}); install the course where {user} "
            f"can read it (see docs/autograder.md), or set GEOMLIB_SANDBOX_USER= to grade without a sandbox user"
        )


def _grade_one(sub: Submission, lab: str, out: Path, timeout: float) -> tuple[dict, str]:
    """Grade one submission in its own process; returns (results, status) and writes them under ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    results = out / "results.json"
    results.unlink(missing_ok=True)
    work = Path(tempfile.mkdtemp(prefix="geomlib-grade-all-"))
    try:
        os.chmod(work, 0o755)
        try:
            skipped = copy_lab(find_lab(sub.folder, lab), work / "labs" / lab)
        except SubmissionError as e:
            data = _failure(f"Nothing was graded: {e}.")
            results.write_text(json.dumps(data, indent=1) + "\n")
            return data, "no lab"
        env = {**os.environ, "GEOMLIB_SANDBOX_USER": sandbox_user()}
        env.setdefault("GEOMLIB_NO_FEEDBACK_PICTURES", "1")
        cmd = [sys.executable, "-m", "geomlib.cli", "grade", "--impl", str(work / "labs"), "--lab", lab]
        cmd += ["--results", str(results), "--feedback", str(out / "feedback")]
        with open(out / "grader-output.txt", "w") as log:
            if skipped:
                log.write("".join(f"not copied: {s}\n" for s in skipped))
                log.flush()
            p = subprocess.Popen(
                cmd, stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, env=env, start_new_session=True
            )
            try:
                code = p.wait(timeout=timeout)
                status = "ok" if code == 0 else f"grader exit {code}"
            except subprocess.TimeoutExpired:
                status = f"timed out after {timeout:g} s"
            finally:
                # Whatever it started (grader, workers, their children) goes with it.
                with contextlib.suppress(ProcessLookupError, PermissionError):
                    os.killpg(p.pid, signal.SIGKILL)
                p.wait()
        try:
            data = json.loads(results.read_text())
        except (OSError, ValueError):
            data = _failure(f"The grader did not produce a result for this submission ({status}).")
            results.write_text(json.dumps(data, indent=1) + "\n")
            status = status if status != "ok" else "no results.json"
        return data, status
    finally:
        shutil.rmtree(work, ignore_errors=True)


def grade_all(
    submissions: Path, lab: str, out: Path, *, jobs: int | None = None, timeout: float = 1800.0, log=print
) -> dict:
    """Grade every submission of ``lab`` under ``submissions`` into ``out``; returns a summary.

    Returns
    -------
    dict
        ``graded`` (submissions with a results.json from the grader), ``failed`` (ids whose grading
        itself failed, or that hold no lab), ``csv`` (path of scores.csv), ``seconds``.
    """
    from geomlib.grading import impl as _impl
    from geomlib.grading.points import points_by_part

    if lab not in _impl.lab_names():
        raise BatchError(f"unknown lab {lab!r}; known: {', '.join(_impl.lab_names())}")
    subs = discover(Path(submissions))
    check_sandbox_user(sandbox_user())
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    parts = points_by_part([lab]).get(lab, {})
    jobs = jobs or min(4, os.cpu_count() or 1)
    ids: dict[str, str] = {}
    for s in subs:
        base = _safe(s.id)
        k, name = 2, base
        while name in ids.values():
            name, k = f"{base}-{k}", k + 1
        ids[s.id] = name
    t0 = time.time()
    rows: dict[str, dict] = {}
    failed: list[str] = []
    log(f"grading {len(subs)} submission(s) of {lab} with {jobs} job(s) into {out}")
    with ThreadPoolExecutor(max_workers=jobs) as pool:
        futures = {pool.submit(_grade_one, s, lab, out / ids[s.id], timeout): s for s in subs}
        for done, fut in enumerate(as_completed(futures), start=1):
            s = futures[fut]
            try:
                data, status = fut.result()
            except Exception as e:  # a bug in this loop must not lose the other submissions
                data, status = _failure(f"grading failed: {type(e).__name__}: {e}"), "error"
            per_part = {p: 0.0 for p in parts}
            for t in data.get("tests", []):
                tags = t.get("tags") or []
                part = tags[1] if len(tags) > 1 else None
                if part in per_part:
                    per_part[part] += float(t.get("score", 0))
            rows[s.id] = {"data": data, "status": status, "parts": per_part}
            if status != "ok":
                failed.append(s.id)
            total = sum(t.get("max_score", 0) for t in data.get("tests", []))
            log(
                f"[{done}/{len(subs)}] {s.id}: {data.get('score', 0):g}/{total:g}"
                + ("" if status == "ok" else f"  ({status})")
                + f"  {time.time() - t0:.0f} s"
            )
    csv_path = out / "scores.csv"
    maxima = {p: pub + hid for p, (pub, hid) in parts.items()}
    with open(csv_path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["submission", "name", "sid", "email", "score", "max", "status"] + list(parts))
        top = f"{sum(maxima.values()):g}"
        w.writerow(["(max)", "", "", "", top, top, ""] + [f"{maxima[p]:g}" for p in parts])
        for s in subs:
            r = rows[s.id]
            w.writerow(
                [ids[s.id], "; ".join(s.names), "; ".join(s.sids), "; ".join(s.emails)]
                + [f"{r['data'].get('score', 0):g}", f"{sum(maxima.values()):g}", r["status"]]
                + [f"{r['parts'][p]:g}" for p in parts]
            )
    seconds = time.time() - t0
    log(f"wrote {csv_path} ({len(subs) - len(failed)} graded, {len(failed)} failed) in {seconds:.0f} s")
    return {"graded": len(subs) - len(failed), "failed": failed, "csv": csv_path, "seconds": seconds}
