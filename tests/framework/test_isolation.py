"""Isolation of student code from the network and from other submissions (issue 23, items 2 and 3).

Planted submissions of the sample course: one sends UDP datagrams to sockets this test listens on
(loopback only), one spies on a victim graded beside it by ``geomlib grade-all``.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import socket
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

from geomlib.grading import landlock, seccomp
from geomlib.grading.results import plain_text

from .course import grade, sandbox_python, sandbox_user_problem

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="the sandbox is Linux-only")

GOOD_OPS = (Path(__file__).parent / "sample_course" / "solutions" / "sample" / "ops.py").read_text()
TASK_BODY = "    c = V.mean(axis=0)\n"


def _submission(base: Path, name: str, ops: str) -> Path:
    """``base/name/sample/`` holding ``ops``; returns ``base/name`` (what ``--impl`` takes)."""
    d = base / name / "sample"
    d.mkdir(parents=True)
    (d / "ops.py").write_text(ops)
    (d / "__init__.py").write_text("")
    for p in (base, base / name, d):
        p.chmod(0o755)  # the sandbox user may read it where it is used
    return d.parent


def _planted(code: str) -> str:
    """The reference solution with ``code`` run first in scale_about_centroid."""
    assert TASK_BODY in GOOD_OPS
    return GOOD_OPS.replace(TASK_BODY, code + TASK_BODY)


# ---------------------------------------------------------------------------------- UDP (item 3)


def _udp_listeners():
    out = []
    for family, host in ((socket.AF_INET, "127.0.0.1"), (socket.AF_INET6, "::1")):
        try:
            s = socket.socket(family, socket.SOCK_DGRAM)
            s.bind((host, 0))
        except OSError:
            continue  # no IPv6 loopback here
        s.settimeout(0.5)
        out.append((s, host, s.getsockname()[1]))
    return out


@pytest.mark.parametrize("landlock_on", ["1", "0"], ids=["with-landlock", "without-landlock"])
def test_a_udp_datagram_from_student_code_never_arrives_and_the_grade_survives(sample_course, tmp_path, landlock_on):
    listeners = _udp_listeners()
    assert listeners, "no loopback UDP socket could be opened here"
    targets = [(host, port) for _, host, port in listeners]
    send = f"""    import socket as _socket
    for _host, _port in {targets!r}:
        try:
            with _socket.socket(_socket.AF_INET6 if ":" in _host else _socket.AF_INET, _socket.SOCK_DGRAM) as _u:
                _u.sendto(b"LEAK from student code", (_host, _port))
        except OSError:
            pass
"""
    sub = _submission(tmp_path, "udp", _planted(send))
    try:
        r = grade(sample_course, str(sub), env={"GEOMLIB_SANDBOX_USER": "", "GEOMLIB_LANDLOCK": landlock_on})
        received = []
        for s, host, _ in listeners:
            with contextlib.suppress(TimeoutError, OSError):
                received.append((host, s.recvfrom(100)[0]))
    finally:
        for s, _, _ in listeners:
            s.close()
    assert received == [], f"student code sent UDP datagrams out of the sandbox: {received}"
    assert r["score"] == 7, [t["name"] for t in r["tests"] if t["status"] != "passed"]


@pytest.mark.skipif(not seccomp.available(), reason="the seccomp filter is written for Linux x86_64/aarch64")
def test_the_seccomp_filter_leaves_unix_sockets_and_takes_every_other_family():
    r, w = os.pipe()
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the child reports through the pipe
        try:
            seccomp.deny_network()
            got = {}
            for name in ("AF_INET", "AF_INET6", "AF_PACKET", "AF_NETLINK", "AF_UNIX"):
                kind = socket.SOCK_RAW if name in ("AF_PACKET", "AF_NETLINK") else socket.SOCK_DGRAM
                try:
                    socket.socket(getattr(socket, name), kind).close()
                    got[name] = "ok"
                except OSError as e:
                    got[name] = e.errno
            a, b = socket.socketpair()
            got["socketpair"] = "ok"
            os.write(w, json.dumps(got).encode())
        finally:
            os._exit(0)
    os.close(w)
    os.waitpid(pid, 0)
    got = json.loads(os.read(r, 4096))
    os.close(r)
    import errno

    assert got == {
        "AF_INET": errno.EPERM,
        "AF_INET6": errno.EPERM,
        "AF_PACKET": errno.EPERM,
        "AF_NETLINK": errno.EPERM,
        "AF_UNIX": "ok",
        "socketpair": "ok",
    }


# ---------------------------------------------------------------------------------- grade-all (item 2)

#: The victim's task holds a secret and stays in the sandbox long enough to be spied on (each of its
#: three calls: its grading outlasts the spy's calls, which take milliseconds once they see it).
VICTIM = """    import time as _time

    _secret = "VICTIM-SECRET-1234"
    _time.sleep(1.0)
"""

#: The spy waits until the victim is being graded beside it (a second grade-all work folder in the
#: temporary folder they share), then tries to read the victim's code, write into every other
#: numba cache and signal every other worker; it reports what it managed in its exception.
SPY = """    import glob as _glob
    import json as _json
    import os as _os
    import time as _time

    _base = _os.path.dirname(_os.path.dirname(_os.path.dirname(_os.getcwd())))  # TMPDIR: sandbox/lab-*/sample
    _report = {"alive": False, "read": [], "wrote": [], "signalled": []}
    _t0 = _time.time()
    while _time.time() - _t0 < 5 and not _report["alive"]:
        try:
            _report["alive"] = sum(n.startswith("geomlib-grade-all-") for n in _os.listdir(_base)) >= 2
        except OSError:
            break  # cannot even list the folder (Landlock)
        _time.sleep(0.1)
    for _p in _glob.glob(_os.path.join(_base, "geomlib-grade-all-*", "labs", "sample", "ops.py")):
        try:
            if "VICTIM-" + "SECRET" in open(_p).read():  # not its own copy
                _report["read"].append(_p)
        except OSError:
            pass
    for _d in _glob.glob(_os.path.join(_base, "geomlib-sandbox-*", "numba-cache")):
        if _d != _os.path.dirname(_os.environ.get("NUMBA_CACHE_DIR", "")):  # its own run's: numba-cache/jit-*
            try:
                with open(_os.path.join(_d, "spy-was-here"), "w") as _f:
                    _f.write("x")
                _report["wrote"].append(_d)
            except OSError:
                pass
    for _pid in _os.listdir("/proc"):
        if _pid.isdigit() and int(_pid) != _os.getpid():
            try:
                if b"geomlib.grading.zygote" in open(f"/proc/{_pid}/cmdline", "rb").read():
                    _os.kill(int(_pid), 0)
                    _report["signalled"].append(int(_pid))
            except OSError:
                pass
    raise RuntimeError("SPY-REPORT " + _json.dumps(_report) + " END")
"""


def _spy_reports(results: dict) -> list[dict]:
    import re

    found = []
    for t in results["tests"]:
        for m in re.finditer(r"SPY-REPORT (\{.*?\}) END", plain_text(t.get("output", ""))):
            found.append(json.loads(m.group(1)))
    return found


@pytest.mark.skipif(os.geteuid() != 0, reason="separate users per submission need root")
@pytest.mark.parametrize(
    "landlock_on, user",
    [("0", None), ("1", None), ("1", "")],
    ids=["private-uids-without-landlock", "private-uids-with-landlock", "landlock-only"],
)
def test_grade_all_keeps_a_spying_submission_away_from_its_neighbour(sample_course, tmp_path, landlock_on, user):
    """The spy reads nothing of the victim's, writes nothing of its and signals none of its processes:
    as root each submission runs as a uid of its own (with or without Landlock); with Landlock and no
    sandbox user (what a non-root instructor gets) Landlock alone keeps them apart (signals: ABI 6+)."""
    if landlock_on == "1" and landlock.abi_version() < (6 if user == "" else 1):
        pytest.skip("this kernel's Landlock is missing or too old (signal scoping needs ABI 6)")
    found = sandbox_python("nobody")
    if found is None:
        pytest.skip(sandbox_user_problem("nobody"))
    python, extra = found
    shared_tmp = Path(tempfile.mkdtemp(prefix="geomlib-spy-tmp-"))  # where both submissions' folders go
    shared_tmp.chmod(0o755)
    subs = Path(tempfile.mkdtemp(prefix="geomlib-spy-subs-"))
    try:
        _submission(subs, "a-spy", _planted(SPY))
        _submission(subs, "b-victim", _planted(VICTIM))
        out = subs / "out"
        env = {"GEOMLIB_LANDLOCK": landlock_on, "TMPDIR": str(shared_tmp), **extra}
        env["PYTHONPATH"] = os.pathsep.join([str(sample_course), extra.get("PYTHONPATH", "")]).rstrip(os.pathsep)
        e = {k: v for k, v in os.environ.items() if k != "GEOMLIB_SANDBOX_USER"}
        if user is not None:
            e["GEOMLIB_SANDBOX_USER"] = user
        p = subprocess.run(
            [python, "-m", "geomlib.cli", "grade-all", str(subs), "--lab", "sample", "--out", str(out), "--jobs", "2"],
            cwd=sample_course, capture_output=True, text=True, timeout=600,
            env={**e, "GEOMLIB_ROOT": str(sample_course), "GEOMLIB_NO_FEEDBACK_PICTURES": "1", **env},
        )  # fmt: skip
        assert p.returncode == 0, p.stdout + p.stderr
        victim = json.loads((out / "b-victim" / "results.json").read_text())
        reports = _spy_reports(json.loads((out / "a-spy" / "results.json").read_text()))
    finally:
        shutil.rmtree(subs, ignore_errors=True)
        shutil.rmtree(shared_tmp, ignore_errors=True)
    assert victim["score"] == 7
    assert reports, "the spy never ran"
    if landlock_on == "0":
        assert any(r["alive"] for r in reports), "the spy never saw the victim being graded beside it"
    assert [r for r in reports if r["read"] or r["wrote"] or r["signalled"]] == [], reports


@pytest.mark.skipif(os.geteuid() != 0, reason="private uids are given as root only")
def test_two_concurrent_grade_all_runs_never_share_a_private_uid(tmp_path):
    from geomlib.grading.batch import UidPool, _remove_files_of

    a, b = UidPool(), UidPool()  # two runs at once (two instructors, two test workers)
    ua, fa = a.take()
    ub, fb = b.take()
    assert ua != ub
    a.release(fa)
    ua2, fa2 = a.take()
    assert ua2 not in (ua, ub)  # a run never gives a uid twice; b still holds ub
    # What a submission left in /tmp under its uid goes with it.
    left = Path(tempfile.mkdtemp(prefix="geomlib-left-by-uid-", dir="/tmp"))
    (left / "data").write_text("x")
    for p in (left, left / "data"):
        os.chown(p, ua2, ua2)
    _remove_files_of(ua2)
    assert not left.exists()
    for pool, fd in ((a, fa2), (b, fb)):
        pool.release(fd)
