"""A seccomp filter (through ctypes) that takes network sockets away from a sandboxed worker.

Landlock (ABI 4+) blocks TCP ``connect``/``bind`` only; UDP, raw and other socket families stay
open, and a kernel without Landlock blocks nothing. :func:`deny_network` installs a classic-BPF
seccomp filter on the calling thread (inherited by every thread and process it starts, and
irreversible) so that

- ``socket()`` succeeds for ``AF_UNIX`` only; every other family (``AF_INET``, ``AF_INET6``,
  ``AF_PACKET``, ``AF_NETLINK``, ``AF_VSOCK``, ...) fails with ``EPERM``;
- ``io_uring_setup`` fails with ``EPERM`` (an io_uring can create sockets without ``socket()``);
- on x86_64, x32 system calls and, on both x86_64 and aarch64, calls made through another
  architecture's entry point (32-bit compatibility: ``socketcall``) fail with ``EPERM``.

Nothing else is filtered. Unprivileged processes may install a filter once ``PR_SET_NO_NEW_PRIVS``
is set, which this module sets (Landlock sets it too).
"""

from __future__ import annotations

import ctypes
import errno
import os
import platform
import struct

__all__ = ["available", "deny_network", "SeccompError"]

_PR_SET_NO_NEW_PRIVS = 38
_PR_SET_SECCOMP = 22
_SECCOMP_MODE_FILTER = 2
_RET_ALLOW = 0x7FFF0000
_RET_ERRNO = 0x00050000

# BPF opcodes: load a 32-bit word of seccomp_data, compare, return.
_LD_ABS = 0x20  # BPF_LD | BPF_W | BPF_ABS
_JEQ = 0x15  # BPF_JMP | BPF_JEQ | BPF_K
_JGE = 0x35  # BPF_JMP | BPF_JGE | BPF_K
_RET = 0x06  # BPF_RET | BPF_K

# offsetof(struct seccomp_data, ...): nr, arch, args[0] (low 32 bits on little-endian machines).
_NR, _ARCH, _ARG0 = 0, 4, 16

_AF_UNIX = 1
_X32_BIT = 0x40000000
#: machine → (AUDIT_ARCH_*, __NR_socket, __NR_io_uring_setup)
_ARCHS = {
    "x86_64": (0xC000003E, 41, 425),
    "aarch64": (0xC00000B7, 198, 425),
}


class SeccompError(OSError):
    """The kernel refused the filter."""


def available() -> bool:
    """Whether this machine's architecture is one the filter is written for (Linux x86_64, aarch64)."""
    return platform.system() == "Linux" and platform.machine() in _ARCHS


def _program(machine: str) -> bytes:
    arch, nr_socket, nr_io_uring = _ARCHS[machine]
    deny = _RET_ERRNO | errno.EPERM
    # (opcode, jump-if-true label, jump-if-false label, k); labels are "next", "allow" or "deny".
    code: list[tuple[int, str, str, int]] = [
        (_LD_ABS, "next", "next", _ARCH),
        (_JEQ, "next", "deny", arch),
        (_LD_ABS, "next", "next", _NR),
    ]
    if machine == "x86_64":
        code.append((_JGE, "deny", "next", _X32_BIT))
    code += [
        (_JEQ, "deny", "next", nr_io_uring),
        (_JEQ, "next", "allow", nr_socket),
        (_LD_ABS, "next", "next", _ARG0),
        (_JEQ, "allow", "deny", _AF_UNIX),
    ]
    allow_at, deny_at = len(code), len(code) + 1
    out = b""
    for i, (op, jt, jf, k) in enumerate(code):
        where = {"next": i + 1, "allow": allow_at, "deny": deny_at}
        out += struct.pack("<HBBI", op, where[jt] - i - 1, where[jf] - i - 1, k)
    out += struct.pack("<HBBI", _RET, 0, 0, _RET_ALLOW)
    out += struct.pack("<HBBI", _RET, 0, 0, deny)
    return out


class _SockFprog(ctypes.Structure):
    _fields_ = [("len", ctypes.c_ushort), ("filter", ctypes.c_void_p)]


def deny_network() -> None:
    """Install the filter described in the module docstring on this thread (and its future children).

    Raises
    ------
    SeccompError
        Not Linux x86_64/aarch64, or the kernel refused ``PR_SET_NO_NEW_PRIVS`` or the filter.
    """
    if not available():
        raise SeccompError(f"no seccomp filter for {platform.system()} {platform.machine()}")
    prog = _program(platform.machine())
    buf = ctypes.create_string_buffer(prog, len(prog))
    fprog = _SockFprog(len(prog) // 8, ctypes.addressof(buf))
    libc = ctypes.CDLL(None, use_errno=True)
    libc.prctl.argtypes = [ctypes.c_int, ctypes.c_ulong, ctypes.c_void_p, ctypes.c_ulong, ctypes.c_ulong]
    if libc.prctl(_PR_SET_NO_NEW_PRIVS, 1, None, 0, 0) != 0:
        err = ctypes.get_errno()
        raise SeccompError(err, f"prctl(PR_SET_NO_NEW_PRIVS): {os.strerror(err)}")
    if libc.prctl(_PR_SET_SECCOMP, _SECCOMP_MODE_FILTER, ctypes.byref(fprog), 0, 0) != 0:
        err = ctypes.get_errno()
        raise SeccompError(err, f"prctl(PR_SET_SECCOMP): {os.strerror(err)}")
