"""Isolation of student code from the network and from other submissions (issue 23, items 2 and 3).

Planted submissions of the sample course: one sends UDP datagrams to sockets this test listens on
(loopback only), one spies on a victim graded beside it by ``geomlib grade-all``.
"""

from __future__ import annotations

import contextlib
import json
import os
import socket
import sys
from pathlib import Path

import pytest

from geomlib.grading import seccomp

from .course import grade

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
