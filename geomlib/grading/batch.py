"""``geomlib grade-all SUBMISSIONS_DIR --lab NAME --out DIR``: grade many submissions of one lab.

``SUBMISSIONS_DIR`` is either a folder per student (any names) or Gradescope's "Export
Submissions" download unzipped: ``submission_metadata.yml`` plus one ``submission_<id>/`` folder
per submission (the metadata gives the students' names, ids and e-mails). Each submission is found
(``<lab>/`` or ``labs/<lab>/``), copied without following links into a private temporary folder and
graded by ``geomlib grade`` in its own process, several at once (``--jobs``). A submission that
crashes, hangs past ``--timeout`` or holds no lab costs only its own row.

As root, every submission's student code runs as a uid of its own (:class:`UidPool`), with a Python
every such uid can run (:func:`sandbox_interpreter`): no submission can read, write or signal
another's, with or without Landlock (docs/autograder.md explains why one shared user would not do).

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
import stat
import subprocess
import sys
import tempfile
import threading
import time
from concurrent.futures import ThreadPoolExecutor, as_completed
from dataclasses import dataclass, field
from pathlib import Path

from geomlib.grading.settings import env as setting
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
    return setting("GEOMLIB_SANDBOX_USER", default)


#: Where the private uids of ``grade-all`` come from (``GEOMLIB_SANDBOX_UIDS=FIRST-LAST`` overrides;
#: ``GEOMLIB_SANDBOX_UIDS=none`` runs every submission as the one sandbox user). The first range is
#: unused by convention (above systemd's container range, below 2^31); the second serves containers
#: whose user namespace maps only 65536 ids (Debian allocates it on demand only; taken ids are skipped).
UID_RANGES = ((2_000_000_000, 2_000_999_999), (60_000, 64_999))


def _mapped(n: int) -> bool:
    """Whether uid and gid ``n`` exist in this user namespace (all of them outside one)."""
    for kind in ("uid_map", "gid_map"):
        try:
            rows = [line.split() for line in Path(f"/proc/self/{kind}").read_text().splitlines()]
        except OSError:
            continue
        if not any(int(inside) <= n < int(inside) + int(count) for inside, _, count in rows):
            return False
    return True


def _ids_in_use() -> set[int]:
    """uids and gids that are named (passwd, group) or run a process now."""
    import grp
    import pwd

    used = {p.pw_uid for p in pwd.getpwall()} | {p.pw_gid for p in pwd.getpwall()} | {g.gr_gid for g in grp.getgrall()}
    for name in os.listdir("/proc"):
        if name.isdigit():
            with contextlib.suppress(OSError):
                st = os.stat(f"/proc/{name}")
                used |= {st.st_uid, st.st_gid}
    return used


def _uid_ranges() -> list[tuple[int, int]]:
    spec = setting("GEOMLIB_SANDBOX_UIDS", "")
    if spec:
        m = re.fullmatch(r"\s*(\d+)\s*-\s*(\d+)\s*", spec)
        if not m or int(m.group(1)) < 1000 or int(m.group(1)) > int(m.group(2)):
            raise BatchError(f"GEOMLIB_SANDBOX_UIDS={spec!r} is not a range FIRST-LAST of uids (FIRST >= 1000)")
        return [(int(m.group(1)), int(m.group(2)))]
    return [r for r in UID_RANGES if _mapped(r[0]) and _mapped(r[1])]


class UidPool:
    """Private uids for the submissions of one ``grade-all`` run, never two at once for one uid.

    A uid is taken by holding an exclusive ``flock`` on ``/run/geomlib-sandbox-uids/<uid>`` (a
    root-only folder) while its submission is graded, so concurrent ``grade-all`` runs (or test
    workers) never share one; the kernel drops the lock if the process dies. Within one run no uid is
    given twice.
    """

    def __init__(self):
        self.ranges = _uid_ranges()
        base = Path("/run") if Path("/run").is_dir() else Path("/var/tmp")
        self.locks = base / "geomlib-sandbox-uids"
        with contextlib.suppress(FileExistsError):
            self.locks.mkdir(mode=0o700)
        st = os.lstat(self.locks)
        if not stat.S_ISDIR(st.st_mode) or st.st_uid != 0 or st.st_mode & 0o022:
            raise BatchError(f"{self.locks} must be a folder of root's that only root can write")
        self.given: set[int] = set()
        self.mutex = threading.Lock()

    def take(self) -> tuple[int, int]:
        """A free uid and the descriptor holding its lock (give it back with :meth:`release`)."""
        import fcntl

        with self.mutex:
            in_use = _ids_in_use()
            for first, last in self.ranges:
                for n in range(first, last + 1):
                    if n in in_use or n in self.given:
                        continue
                    fd = os.open(self.locks / str(n), os.O_CREAT | os.O_RDWR | os.O_NOFOLLOW | os.O_CLOEXEC, 0o600)
                    try:
                        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                    except OSError:
                        os.close(fd)
                        continue
                    self.given.add(n)
                    return n, fd
        raise BatchError(
            f"no free uid left in {setting('GEOMLIB_SANDBOX_UIDS') or UID_RANGES}; "
            f"set GEOMLIB_SANDBOX_UIDS=FIRST-LAST to a free range"
        )

    @staticmethod
    def release(fd: int) -> None:
        os.close(fd)


def _remove_files_of(uid: int) -> None:
    """Remove what ``uid`` left in the world-writable folders (possible without Landlock only)."""
    for top in ("/tmp", "/var/tmp", "/dev/shm"):
        todo = [Path(top)]
        for folder in todo:
            with contextlib.suppress(OSError):
                for entry in os.scandir(folder):
                    with contextlib.suppress(OSError):
                        st = entry.stat(follow_symlinks=False)
                        if st.st_uid == uid:
                            if entry.is_dir(follow_symlinks=False):
                                shutil.rmtree(entry.path, ignore_errors=True)
                            else:
                                os.unlink(entry.path)
                        elif stat.S_ISDIR(st.st_mode) and st.st_mode & 0o002 and folder == Path(top):
                            todo.append(Path(entry.path))  # a world-writable folder one level down


def _kill_uid(uid: int) -> None:
    """SIGKILL every process of ``uid`` (a submission's private uid, after its grading)."""
    for _ in range(20):
        pids = []
        for name in os.listdir("/proc"):
            if name.isdigit():
                with contextlib.suppress(OSError):
                    if os.stat(f"/proc/{name}").st_uid == uid:
                        pids.append(int(name))
        if not pids:
            return
        for pid in pids:
            with contextlib.suppress(ProcessLookupError, PermissionError):
                os.kill(pid, signal.SIGKILL)
        time.sleep(0.05)


def check_sandbox_user(user: str, python: str | None = None) -> None:
    """Fail clearly unless ``user`` (a name or a uid) can run ``python`` and import the grader's worker.

    A Python the sandbox user cannot read (one installed under ``/root``, say) would otherwise make
    student code fail on its first import, and the message would blame the student.
    """
    if not user or os.geteuid() != 0:
        return
    from geomlib.grading.zygote import sandbox_ids

    python = python or sys.executable
    # The zygote's own search path (geomlib.grading.sandbox): this geomlib first.
    here = str(Path(__file__).resolve().parents[2])
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([here, os.environ.get("PYTHONPATH", "")]).rstrip(os.pathsep)}
    try:
        uid, gid = sandbox_ids(user)
        p = subprocess.run(
            [python, "-s", "-c", "import numpy, geomlib.grading.worker"], cwd="/", env=env,
            capture_output=True, text=True, timeout=120, user=uid, group=gid, extra_groups=[],
        )  # fmt: skip
        ok, why = p.returncode == 0, (p.stderr.strip().splitlines() or ["?"])[-1]
    except KeyError:
        ok, why = False, "no such user"
    except (OSError, subprocess.TimeoutExpired) as e:
        ok, why = False, str(e)
    if not ok:
        raise BatchError(
            f"the sandbox user {user!r} cannot run {python} ({why}); install the course where {user} "
            f"can read it (see docs/autograder.md), or set GEOMLIB_SANDBOX_USER= to grade without a sandbox user"
        )


#: Where ``grade-all`` builds an environment the sandbox user can run, when the grader's own
#: Python lives where that user cannot read it (``uv sync`` links ``.venv`` to a Python under /root).
SANDBOX_VENV = ".venv-sandbox"
#: The autograder's choice of system Python, in order: read from the one set-up script
#: (``geomlib/grading/setup.sh``'s ``for cand in …`` line), so grade-all and the autograder agree.
PYTHON_CANDIDATES = tuple(
    re.search(r"^for cand in ([^;]+); do$", Path(__file__).with_name("setup.sh").read_text(), re.M).group(1).split()
)


def _uv() -> list[str]:
    """How to run uv: ``$UV`` (set by ``uv run``), ``uv`` on the PATH, the private copy ``./run``
    installed (:func:`.bootstrap.private_uv`: ``.venv/bin/geomlib`` typed in a shell whose PATH lacks
    ``~/.local/bin``), else ``python3 -m uv``."""
    from geomlib.grading import bootstrap

    if os.environ.get("UV") and os.access(os.environ["UV"], os.X_OK):
        return [os.environ["UV"]]
    if shutil.which("uv"):
        return [shutil.which("uv")]
    private = bootstrap.private_uv()
    if os.access(private, os.X_OK):
        return [private]
    return [shutil.which("python3") or "python3", "-m", "uv"]


def _runs(user: str, python: str) -> bool:
    try:
        check_sandbox_user(user, python)
    except BatchError:
        return False
    return True


def sandbox_interpreter(user: str, log=print) -> str:
    """A Python that both root and the sandbox user can grade with: this one if the user can run it.

    Else the course's ``.venv-sandbox``, made as the autograder's ``setup.sh`` makes its environment:
    ``GEOMLIB_AUTOGRADER_PYTHON``, else a system ``python3.11``, else ``uv python install 3.11`` into
    ``.python-sandbox`` (all readable by everyone), then ``uv sync --frozen --no-dev --group grading``.
    """
    from geomlib.grading.zygote import sandbox_ids

    try:
        sandbox_ids(user)
    except KeyError:
        return sys.executable  # no such user: check_sandbox_user says so
    if not user or os.geteuid() != 0 or _runs(user, sys.executable):
        return sys.executable
    from geomlib.grading import impl as _impl

    root = _impl.course_root()
    venv = root / SANDBOX_VENV
    python = venv / "bin" / "python"
    if not ((root / "pyproject.toml").is_file() and (root / "uv.lock").is_file()):
        return sys.executable  # not a checkout: check_sandbox_user says what is wrong
    doing = f"checking {venv} against uv.lock" if python.is_file() else f"making {venv}"
    log(f"the sandbox user cannot run {sys.executable}; {doing} as the autograder's setup.sh does")
    env = {**os.environ, "UV_PROJECT_ENVIRONMENT": str(venv)}
    env.pop("VIRTUAL_ENV", None)
    # Bytecode compiled now (the sandbox user cannot write it), unless uv's own UV_COMPILE_BYTECODE=0 says not to.
    env.setdefault("UV_COMPILE_BYTECODE", "1")
    base = setting("GEOMLIB_AUTOGRADER_PYTHON") or next((c for c in PYTHON_CANDIDATES if os.access(c, os.X_OK)), "")
    try:
        if not base:
            env["UV_PYTHON_INSTALL_DIR"] = str(root / ".python-sandbox")
            subprocess.run([*_uv(), "python", "install", "3.11"], env=env, check=True, capture_output=True, text=True)
            base = subprocess.run(
                [*_uv(), "python", "find", "3.11"], env=env, check=True, capture_output=True, text=True
            ).stdout.strip()
            subprocess.run(["chmod", "-R", "a+rX", env["UV_PYTHON_INSTALL_DIR"]], check=True)
        subprocess.run(
            [*_uv(), "sync", "--frozen", "--no-dev", "--group", "grading", "--python", base,
             "--no-python-downloads", "--quiet"],
            cwd=root, env=env, check=True, capture_output=True, text=True,
        )  # fmt: skip
        subprocess.run(["chmod", "-R", "a+rX", str(venv)], check=True)
    except (OSError, subprocess.CalledProcessError) as e:
        why = (getattr(e, "stderr", "") or str(e)).strip().splitlines()[-1:] or [str(e)]
        raise BatchError(f"could not make {venv} for the sandbox user {user!r}: {why[0]}") from None
    log(f"grading with {python} (Python {base})")
    return str(python)


def _prune_empty(folder: Path) -> None:
    """Remove ``folder`` and its sub-folders where they hold no file (no pictures were drawn)."""
    if not folder.is_dir() or folder.is_symlink():
        return
    for dirpath, _, _ in sorted(os.walk(folder), key=lambda w: -len(w[0])):
        with contextlib.suppress(OSError):
            os.rmdir(dirpath)  # fails, as it should, on a folder that is not empty


def _grade_one(
    sub: Submission, lab: str, out: Path, timeout: float, user: str | None = None, python: str | None = None
) -> tuple[dict, str]:
    """Grade one submission in its own process; returns (results, status) and writes them under ``out``.

    ``user`` is the sandbox user of this submission (a private uid as root), else :func:`sandbox_user`.
    """
    out.mkdir(parents=True, exist_ok=True)
    results = out / "results.json"
    results.unlink(missing_ok=True)
    # Private (0700, the grading user's): the grader reads the copy and makes the worker's snapshot.
    work = Path(tempfile.mkdtemp(prefix="geomlib-grade-all-"))
    user = sandbox_user() if user is None else user
    try:
        try:
            skipped = copy_lab(find_lab(sub.folder, lab), work / lab)  # `work` is the implementation graded
        except SubmissionError as e:
            data = _failure(f"Nothing was graded: {e}.")
            results.write_text(json.dumps(data, indent=1) + "\n")
            return data, "no lab"
        env = {**os.environ, "GEOMLIB_SANDBOX_USER": user}
        env.setdefault("GEOMLIB_NO_FEEDBACK_PICTURES", "1")
        cmd = [python or sys.executable, "-m", "geomlib.cli", "grade", "--impl", str(work), "--lab", lab]
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
        _prune_empty(out / "feedback")
        if user.isdigit() and os.geteuid() == 0:
            _kill_uid(int(user))  # nothing of this submission outlives its grading
            _remove_files_of(int(user))
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
    user = sandbox_user()
    python = sandbox_interpreter(user, log)
    check_sandbox_user(user, python)
    out = Path(out)
    private = bool(user) and os.geteuid() == 0 and setting("GEOMLIB_SANDBOX_UIDS", "").lower() != "none"
    pool = None
    if private:
        # Every submission's workers run as a uid of their own (and the gid of the same number), so
        # no submission's processes can read, write or signal another's, with or without Landlock.
        pool = UidPool()
        uid, fd = pool.take()
        try:
            check_sandbox_user(str(uid), python)
        finally:
            pool.release(fd)
    out.mkdir(parents=True, exist_ok=True)
    if private:
        for folder in (Path(submissions), out):
            mode = folder.stat().st_mode
            if mode & 0o007:
                folder.chmod(mode & ~0o007)
                log(f"made {folder} private (chmod o-rwx): each submission's code runs as a user of its own")
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

    def job(s: Submission) -> tuple[dict, str]:
        if pool is None:
            return _grade_one(s, lab, out / ids[s.id], timeout, user, python)
        uid, fd = pool.take()
        try:
            return _grade_one(s, lab, out / ids[s.id], timeout, str(uid), python)
        finally:
            pool.release(fd)

    with ThreadPoolExecutor(max_workers=jobs) as workers:
        futures = {workers.submit(job, s): s for s in subs}
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
