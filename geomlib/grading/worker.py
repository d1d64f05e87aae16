"""The worker side of the sandbox: runs one call into student code in a forked child process.

It sets resource limits, sends the student's prints to a file, imports only the module that
defines the requested function (so a syntax error elsewhere in the lab costs only the functions
in that file), calls it, and sends back either the encoded result or a description of what went
wrong. Nothing it sends is unpickled by the grader (see :mod:`geomlib.grading.wire`).
"""

from __future__ import annotations

import ast
import importlib
import json
import os
import resource
import sys
import traceback
import types
from pathlib import Path

from geomlib.grading import wire


def _vm_size_bytes() -> int:
    try:
        with open("/proc/self/statm") as f:
            return int(f.read().split()[0]) * resource.getpagesize()
    except OSError:
        return 0


def _limit_resources(memory_mb: int, cpu_s: float) -> None:
    if memory_mb:
        limit = _vm_size_bytes() + memory_mb * 2**20
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    if cpu_s:
        cpu = int(cpu_s) + 2
        resource.setrlimit(resource.RLIMIT_CPU, (cpu, cpu + 2))
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))


def _drop_privileges() -> None:
    """As root (the autograder), run student code as ``nobody`` so it cannot read hidden references."""
    user = os.environ.get("GEOMLIB_SANDBOX_USER")
    if not user or os.geteuid() != 0:
        return
    import pwd

    pw = pwd.getpwnam(user)
    os.setgroups([])
    os.setgid(pw.pw_gid)
    os.setuid(pw.pw_uid)


def _defines(tree: ast.Module, name: str) -> bool:
    for node in tree.body:
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef) and node.name == name:
            return True
        if isinstance(node, ast.Assign) and any(isinstance(t, ast.Name) and t.id == name for t in node.targets):
            return True
        if isinstance(node, ast.ImportFrom) and any((a.asname or a.name) == name for a in node.names):
            return True
    return False


def find_function(lab_dir: Path, lab: str, function: str):
    """Import the module of ``lab_dir`` that defines ``function`` and return the function.

    The lab's ``__init__.py`` is not executed (it usually imports every module, which would let a
    syntax error in one file break them all); it is searched last.
    """
    pkg_name = f"_graded_{lab}"
    pkg = types.ModuleType(pkg_name)
    pkg.__path__ = [str(lab_dir)]
    pkg.__package__ = pkg_name
    sys.modules[pkg_name] = pkg
    broken = []
    files = sorted(p for p in lab_dir.glob("*.py") if p.name != "__init__.py")
    for path in files + [lab_dir / "__init__.py"]:
        if not path.is_file():
            continue
        try:
            tree = ast.parse(path.read_text(encoding="utf-8", errors="replace"), filename=str(path))
        except SyntaxError as e:
            broken.append(f"{path.name} line {e.lineno}: {e.msg}")
            continue
        if not _defines(tree, function):
            continue
        if path.name == "__init__.py":
            spec = importlib.util.spec_from_file_location(pkg_name, path, submodule_search_locations=[str(lab_dir)])
            mod = importlib.util.module_from_spec(spec)
            sys.modules[pkg_name] = mod
            spec.loader.exec_module(mod)
        else:
            mod = importlib.import_module(f"{pkg_name}.{path.stem}")
        fn = getattr(mod, function, None)
        if fn is not None:
            return fn
    hint = f"; these files have syntax errors: {'; '.join(broken)}" if broken else ""
    raise LookupError(f"could not find a function named {function!r} in {lab_dir.name}/{hint}")


def _student_frames(tb, lab_dir: Path) -> list[dict]:
    frames = []
    for fs in traceback.extract_tb(tb):
        try:
            inside = Path(fs.filename).resolve().is_relative_to(lab_dir.resolve())
        except (OSError, ValueError):
            inside = False
        if inside:
            frames.append(
                {
                    "file": f"{lab_dir.name}/{Path(fs.filename).name}",
                    "line": fs.lineno,
                    "function": fs.name,
                    "code": fs.line or "",
                }
            )
    return frames


def describe_exception(e: BaseException, lab_dir: Path) -> dict:
    if isinstance(e, SyntaxError) and e.filename:
        frames = [
            {
                "file": f"{lab_dir.name}/{Path(e.filename).name}",
                "line": e.lineno,
                "function": "<module>",
                "code": (e.text or "").strip(),
            }
        ]
    else:
        frames = _student_frames(e.__traceback__, lab_dir)
    return {
        "kind": "exception",
        "type": type(e).__name__,
        "mro": [c.__name__ for c in type(e).__mro__],
        "message": str(e)[:4000],
        "frames": frames[-3:],
    }


def run_call(conn, lab_dir: str, lab: str, function: str, args, kwargs, memory_mb: int, cpu_s: float, out_path: str):
    """Entry point of the child process (see :func:`geomlib.grading.sandbox.call`)."""
    lab_path = Path(lab_dir)
    try:
        fd = os.open(out_path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
        os.dup2(fd, 1)
        os.dup2(fd, 2)
        # pytest's capture (and notebooks) replace sys.stdout with objects that bypass fd 1.
        sys.stdout = open(1, "w", closefd=False, errors="replace")  # noqa: SIM115
        sys.stderr = open(2, "w", closefd=False, errors="replace")  # noqa: SIM115
        _limit_resources(memory_mb, cpu_s)
        os.chdir(lab_path)
        _drop_privileges()
    except Exception as e:  # the sandbox itself failed: report, do not blame the student
        conn.send_bytes(json.dumps({"kind": "internal", "message": f"sandbox set-up failed: {e!r}"}).encode())
        os._exit(0)
    try:
        try:
            fn = find_function(lab_path, lab, function)
        except LookupError as e:
            payload = {"kind": "missing", "message": str(e)}
        else:
            result = fn(*args, **kwargs)
            try:
                data = wire.encode(result)
            except wire.WireError as e:
                payload = {"kind": "bad_return", "message": f"{function} returned {e}, which the grader cannot read"}
            else:
                sys.stdout.flush()
                conn.send_bytes(b"R" + data)
                os._exit(0)
    except MemoryError:
        payload = {"kind": "memory", "message": "ran out of memory"}
    except RecursionError as e:
        payload = describe_exception(e, lab_path)
    except SystemExit as e:
        payload = {"kind": "exit", "message": f"called sys.exit({e.code!r})"}
    except BaseException as e:  # noqa: BLE001 - anything the student raises is reported
        payload = describe_exception(e, lab_path)
    try:
        sys.stdout.flush()
        conn.send_bytes(b"E" + json.dumps(payload).encode())
    finally:
        os._exit(0)
