"""``./run``'s system-package step: who may install what (issue 28 item 2, issue 26 item 2).

``./run`` runs with fake ``id``, ``sudo``, ``apt-get``, ``apt-cache`` and ``python3`` on a PATH that
holds nothing else but the shell tools it uses (no ``ldconfig``: it lives in /sbin, off an ordinary
user's PATH). The fake ``python3`` stops ``./run`` right after the system step (the bootstrap of uv
is tested in test_bootstrap.py and the fresh-machine tests), and every fake records its calls.
``GEOMLIB_LIB_DIRS`` names the only folders where ``./run`` may find libOSMesa.
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
TOOLS = ("bash", "grep", "mktemp", "cat", "rm", "uname", "tr", "dirname", "true")


def _fake_machine(
    tmp_path: Path, scripts: dict[str, str], libraries, tools=TOOLS, private: dict[str, str] | None = None
) -> dict[str, str]:
    """A machine for ``./run``: ``fake/`` holds the ``scripts`` (bash bodies by name) first on the PATH,
    ``tools/`` links to the real ``tools``, ``lib/`` empty files named ``libraries`` (the only folder
    where ``./run`` looks for them) and ``private/`` the ``private`` scripts, off the PATH. Returns the
    environment (PATH, HOME, GEOMLIB_LIB_DIRS)."""
    fake, bin_dir, libs = tmp_path / "fake", tmp_path / "tools", tmp_path / "lib"
    for d in (fake, bin_dir, libs):
        d.mkdir()
    for t in tools:
        (bin_dir / t).symlink_to(shutil.which(t) or pytest.skip(f"{t} is not installed"))
    for lib in libraries:
        (libs / lib).write_text("")
    bash = shutil.which("bash")
    places = [(fake, scripts)] + ([(tmp_path / "private", private)] if private is not None else [])
    for folder, bodies in places:
        folder.mkdir(exist_ok=True)
        for name, body in bodies.items():
            (folder / name).write_text(f"#!{bash}\n{body}\n")
            (folder / name).chmod(0o755)
    return {"PATH": f"{fake}:{bin_dir}", "HOME": str(tmp_path), "GEOMLIB_LIB_DIRS": str(libs)}


#: What ``./run`` needs of OpenGL: OSMesa, and libGL and libXrender for pyrender.
OPENGL = ("libOSMesa.so.8", "libGL.so.1", "libXrender.so.1")


def _run(
    tmp_path: Path, *args: str, uid: int, has_osmesa: bool, sudo_ok: bool = False, has_libgl: bool | None = None
) -> tuple[str, list[str]]:
    gl = has_osmesa if has_libgl is None else has_libgl
    libraries = (OPENGL[:1] if has_osmesa else ()) + (OPENGL[1:] if gl else ())
    log = tmp_path / "calls.log"
    scripts = {
        "id": f'[ "$1" = -u ] && echo {uid} || echo "uid={uid}"',
        "sudo": f'echo "sudo $*" >> {log}; ' + ('[ "$1" = -n ] && shift; exec "$@"' if sudo_ok else "exit 1"),
        "apt-get": f'echo "apt-get $*" >> {log}',
        "apt-cache": 'echo "  Candidate: 1.0"',
        "python3": f'echo "python3 $*" >> {log}; exit 1',
    }
    env = _fake_machine(tmp_path, scripts, libraries)
    p = subprocess.run([str(ROOT / "run"), *args], env=env, capture_output=True, text=True, timeout=120)
    assert p.returncode == 1, p.stderr  # stopped by the fake python3, after the system step
    calls = log.read_text().splitlines() if log.exists() else []
    assert calls and calls[-1].startswith("python3 geomlib/grading/bootstrap.py uv"), (calls, p.stderr)
    return p.stderr, calls[:-1]


def test_an_ordinary_user_with_the_library_is_not_asked_anything(tmp_path):
    """The library is there but ldconfig is not on the PATH: nothing to install, no sudo."""
    err, calls = _run(tmp_path, "tests", "-q", "tests/graded/subdivision", uid=1000, has_osmesa=True)
    assert [c for c in calls if c != "sudo -n true"] == [], calls
    assert "installing" not in err and "sudo" not in err, err


def test_an_ordinary_user_without_the_library_is_told_what_to_ask_for_and_goes_on(tmp_path):
    err, calls = _run(tmp_path, "setup", uid=1000, has_osmesa=False)
    assert [c for c in calls if c != "sudo -n true"] == [], calls  # no apt-get, no sudo apt-get
    assert "libosmesa6" in err and "administrator" in err and "going on" in err, err


def test_password_less_sudo_may_install_the_missing_library(tmp_path):
    err, calls = _run(tmp_path, "setup", uid=1000, has_osmesa=False, sudo_ok=True)
    assert any(c.startswith("apt-get install") and "libosmesa6" in c for c in calls), calls


def test_root_installs_the_missing_library_quietly_and_no_browser_for_a_students_run(tmp_path):
    err, calls = _run(tmp_path, "tests", "-q", "tests/graded/subdivision", uid=0, has_osmesa=False)
    installs = [c for c in calls if c.startswith("apt-get install")]
    assert len(installs) == 1 and "libosmesa6" in installs[0] and "chromium" not in installs[0], calls
    assert "chromium" not in err, err


def test_root_installs_libgl_when_only_osmesa_is_there(tmp_path):
    """pyrender imports pyglet's viewer, which loads libGL.so.1 and libXrender.so.1 even to render off
    screen: walked in a Debian 12 root that had libosmesa6 only, `import pyrender` failed with
    'Library "GL" not found' (issue 26). As root ./run installs them; an ordinary user is told to ask."""
    (tmp_path / "root").mkdir()
    (tmp_path / "user").mkdir()
    err, calls = _run(tmp_path / "root", "setup", uid=0, has_osmesa=True, has_libgl=False)
    installs = [c for c in calls if c.startswith("apt-get install")]
    assert len(installs) == 1 and "libosmesa6" not in installs[0], calls
    assert {"libgl1", "libxrender1"} <= set(installs[0].split()), calls
    err, calls = _run(tmp_path / "user", "setup", uid=1000, has_osmesa=True, has_libgl=False)
    assert [c for c in calls if c != "sudo -n true"] == [], calls
    assert "libgl1 libxrender1" in err and "administrator" in err, err


def test_root_without_python3_installs_it_before_the_bootstrap(tmp_path):
    """A minimal Debian 12 (the debian:bookworm image) has no python3: walked as root, ./run installed
    the OpenGL libraries and then stopped at "no python3 on this machine" (issue 26). As root it now
    installs python3 first, as the autograder's setup.sh does."""
    fake, tools, libs = tmp_path / "fake", tmp_path / "tools", tmp_path / "lib"
    for d in (fake, tools, libs):
        d.mkdir()
    for t in TOOLS:
        (tools / t).symlink_to(shutil.which(t) or pytest.skip(f"{t} is not installed"))
    for lib in ("libOSMesa.so.8", "libGL.so.1", "libXrender.so.1"):
        (libs / lib).write_text("")
    log = tmp_path / "calls.log"
    for name, body in {"id": "echo 0", "apt-get": f'echo "apt-get $*" >> {log}'}.items():
        (fake / name).write_text(f"#!{shutil.which('bash')}\n{body}\n")
        (fake / name).chmod(0o755)
    env = {"PATH": f"{fake}:{tools}", "HOME": str(tmp_path), "GEOMLIB_LIB_DIRS": str(libs)}
    p = subprocess.run([str(ROOT / "run"), "setup"], env=env, capture_output=True, text=True, timeout=120)
    assert p.returncode == 1 and "no python3 on this machine" in p.stderr, p.stderr  # the fake apt-get installs nothing
    installs = [c for c in log.read_text().splitlines() if c.startswith("apt-get install")]
    assert len(installs) == 1 and "python3" in installs[0].split(), installs


def test_only_the_whole_suite_installs_the_browser(tmp_path):
    for args, wants_browser in ((("setup",), False), (("figures",), False), (("tests",), True)):
        d = tmp_path / "-".join(args)
        d.mkdir()
        err, calls = _run(d, *args, uid=0, has_osmesa=True)
        browser = [c for c in calls if c.startswith("apt-get install") and "chromium" in c]
        assert bool(browser) == wants_browser, (args, calls, err)


def _run_with_fake_uv(
    tmp_path: Path, *, python_found: bool, install_ok: bool
) -> tuple[subprocess.CompletedProcess, list[str]]:
    """``./run figures`` as root with the library present and a fake uv (``GEOMLIB_UV``) that
    finds no supported Python unless ``python_found``; returns the result and uv's calls."""
    log = tmp_path / "uv.log"
    find = (
        "exit 0"
        if python_found
        else 'echo "error: No interpreter found for Python >=3.10, <3.15 in managed installations or search path" >&2; exit 2'
    )
    uv = f"""echo "uv $*" >> {log}
case "$1 $2" in
  "python find") {find} ;;
  "python install") exit {0 if install_ok else 1} ;;
esac
exit 0
"""
    env = _fake_root_with_osmesa(tmp_path, uv=uv, apt_get=f'echo "apt-get $*" >> {log}')
    p = subprocess.run([str(ROOT / "run"), "figures"], env=env, capture_output=True, text=True, timeout=120)
    return p, (log.read_text().splitlines() if log.exists() else [])


def _fake_root_with_osmesa(tmp_path: Path, *, uv: str, apt_get: str | None = None, private_uv: bool = False,
                           tools: tuple[str, ...] = ()) -> dict[str, str]:  # fmt: skip
    """The environment of a ``./run`` as root (fake ``id``) with libOSMesa present, the shell tools, the
    system ``python3`` and ``tools`` on the PATH, and the fake ``uv`` and ``apt-get`` (none when None)
    given as bash bodies; with ``private_uv`` the uv is a private copy off the PATH (as on a fresh
    machine)."""
    scripts = {"id": "echo 0"} | ({"apt-get": apt_get} if apt_get is not None else {})
    uv_script = {"uv": uv}
    env = _fake_machine(tmp_path, scripts if private_uv else scripts | uv_script, OPENGL, (*TOOLS, "python3", *tools),
                        private=uv_script if private_uv else None)  # fmt: skip
    return {**env, "GEOMLIB_UV": str(tmp_path / ("private" if private_uv else "fake") / "uv")}


def test_a_system_without_a_supported_python_gets_one_from_uv_and_is_told(tmp_path):
    p, calls = _run_with_fake_uv(tmp_path, python_found=False, install_ok=True)
    assert p.returncode == 0, p.stderr
    assert "no Python 3.10-3.14 on this machine: installing Python 3.12 with uv" in p.stderr
    installs = [c for c in calls if c.startswith("uv python install")]
    syncs = [c for c in calls if c.startswith("uv sync")]
    assert installs and "3.12" in installs[0] and syncs and "--python >=3.10,<3.15" in syncs[0], calls
    assert calls.index(installs[0]) < calls.index(syncs[0])


def test_when_uv_cannot_download_a_python_the_message_says_what_to_install(tmp_path):
    p, calls = _run_with_fake_uv(tmp_path, python_found=False, install_ok=False)
    assert p.returncode == 1
    assert "github.com" in p.stderr and "install Python 3.10-3.14 yourself" in p.stderr, p.stderr
    assert not [c for c in calls if c.startswith("uv sync")], calls


def test_a_supported_system_python_is_used_as_it_is(tmp_path):
    p, calls = _run_with_fake_uv(tmp_path, python_found=True, install_ok=True)
    assert p.returncode == 0, p.stderr
    assert not [c for c in calls if c.startswith("uv python install")] and "Python" not in p.stderr, calls


def _root_with_a_private_uv(tmp_path: Path, uv_body: str) -> dict[str, str]:
    """The environment of a ``./run`` as root (fake ``id``) with libOSMesa present and ``uv`` only as a
    private copy off the PATH (as on a fresh machine), given as a bash body."""
    return _fake_root_with_osmesa(tmp_path, uv=uv_body, private_uv=True, tools=("mkdir", "ln"))


def test_every_job_puts_the_private_uv_on_the_guides_path(tmp_path):
    """docs/instructors.md's commands are `uv run geomlib ...` after `./run figures` or `./run tests`:
    every job, not only `setup`, links the uv it found into ~/.local/bin and says so once when that
    folder is off the PATH (a uv outside the PATH, as the private copy is)."""
    env = _root_with_a_private_uv(tmp_path, "exit 0")
    private = tmp_path / "private"
    for job, says in (("figures", True), ("figures", False), ("setup", True)):
        p = subprocess.run([str(ROOT / "run"), job], env=env, capture_output=True, text=True, timeout=120)
        assert p.returncode == 0, p.stderr
        link = tmp_path / ".local" / "bin" / "uv"
        assert link.is_symlink() and link.resolve() == (private / "uv").resolve(), (job, p.stderr)
        assert ("not on your PATH yet" in p.stderr) == says, (job, p.stderr)


def test_the_set_up_of_a_one_lab_bundle_names_its_lab(tmp_path):
    """The student bundle of one lab: `./run setup`'s last line is a command the student can paste
    (it said `--lab LAB` whatever the bundle held); with several labs it stays `LAB`."""
    bash = shutil.which("bash")
    for labs, expected in ((("subdivision",), "--lab subdivision"), (("maps", "sdf"), "--lab LAB")):
        course = tmp_path / "-".join(labs)
        (course / "geomlib" / "grading").mkdir(parents=True)
        shutil.copy2(ROOT / "run", course / "run")
        shutil.copy2(ROOT / "geomlib" / "grading" / "bootstrap.py", course / "geomlib" / "grading" / "bootstrap.py")
        for lab in labs:
            (course / "labs" / lab).mkdir(parents=True)
            (course / "labs" / lab / "README.md").write_text(f"# {lab}\n")
        (course / "uv").write_text(f"#!{bash}\nexit 0")
        (course / "uv").chmod(0o755)
        (course / "lib").mkdir()
        for lib in ("libOSMesa.so.8", "libGL.so.1", "libXrender.so.1"):  # OpenGL
            (course / "lib" / lib).write_text("")
        env = {
            "PATH": f"{Path(shutil.which('python3')).parent}:/usr/bin:/bin",
            "HOME": str(course),
            "GEOMLIB_LIB_DIRS": str(course / "lib"),
            "GEOMLIB_UV": str(course / "uv"),
        }
        p = subprocess.run([str(course / "run"), "setup"], env=env, capture_output=True, text=True, timeout=120)
        assert p.returncode == 0, p.stderr
        last = p.stderr.strip().splitlines()[-1]
        assert last.startswith("[setup] ready") and last.endswith(f"uv run geomlib grade --impl labs {expected}"), (
            p.stderr
        )


def test_the_suite_writes_bytecode_where_the_machine_says_not_to(tmp_path):
    """`./run tests` unsets PYTHONDONTWRITEBYTECODE for the suite's processes (each would compile
    geomlib and rewrite the graded tests again: ~1 s of CPU per grading run); other jobs keep it."""
    log = tmp_path / "uv.log"
    uv = f'[ "$1" = run ] && echo "$* dont_write=${{PYTHONDONTWRITEBYTECODE:-unset}}" >> {log}\nexit 0\n'
    env = {**_fake_root_with_osmesa(tmp_path, uv=uv, apt_get="exit 0"), "PYTHONDONTWRITEBYTECODE": "1"}
    for args in (("tests", "-q", "tests/unit"), ("figures",)):
        p = subprocess.run([str(ROOT / "run"), *args], env=env, capture_output=True, text=True, timeout=120)
        assert p.returncode == 0, p.stderr
    runs = log.read_text().splitlines()
    assert any(r.startswith("run --frozen pytest") and r.endswith("dont_write=unset") for r in runs), runs
    assert any(r.startswith("run --frozen geomlib figures") and r.endswith("dont_write=1") for r in runs), runs


def test_the_suite_finds_the_uv_that_run_found_on_its_path(tmp_path):
    """A fresh machine: uv is the private copy, off the PATH (its ~/.local/bin link too). The suite's
    tests run `uv` themselves (test_release_course.py installs the released autograder with it), so
    `./run tests` gives pytest that uv first on the PATH; it was missing there and 9 release tests
    skipped in a fresh CI clone ("uv is not installed")."""
    log = tmp_path / "uv.log"
    # the private copy: as pytest's process it reports which uv a test would find on its PATH
    env = _root_with_a_private_uv(tmp_path, f'[ "$1" = run ] && echo "$* found=$(command -v uv)" >> {log}\nexit 0\n')
    private = tmp_path / "private"
    for args in (("tests", "-q", "tests/unit"), ("tests",)):
        p = subprocess.run([str(ROOT / "run"), *args], env=env, capture_output=True, text=True, timeout=120)
        assert p.returncode == 0, p.stderr
    runs = log.read_text().splitlines()
    assert len(runs) == 2 and all(r.startswith("run --frozen pytest") for r in runs), runs
    assert all(r.endswith(f"found={private / 'uv'}") for r in runs), runs


def test_the_path_hint_says_whether_the_next_login_adds_it(tmp_path):
    """`./run setup` told root "your next login adds it: ~/.profile does on Debian and Ubuntu", but
    root's /root/.profile does not (only /etc/skel's does): the next `bash -l` said "uv: command not
    found" (fresh-clone walk, issue 26). It now names the login file and says which of the two holds."""
    env = _root_with_a_private_uv(tmp_path, "exit 0")
    (tmp_path / ".profile").write_text("mesg n 2> /dev/null || true\n")  # Debian's /root/.profile
    p = subprocess.run([str(ROOT / "run"), "setup"], env=env, capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr
    assert "to keep it, add that line to ~/.profile" in p.stderr and "next login" not in p.stderr, p.stderr
    skel = 'if [ -d "$HOME/.local/bin" ] ; then\n    PATH="$HOME/.local/bin:$PATH"\nfi\n'  # /etc/skel/.profile
    (tmp_path / ".profile").write_text(skel)
    p = subprocess.run([str(ROOT / "run"), "setup"], env=env, capture_output=True, text=True, timeout=120)
    assert "your next login adds it: ~/.profile does" in p.stderr, p.stderr
    (tmp_path / ".bash_profile").write_text("# bash reads this one instead of ~/.profile\n")
    p = subprocess.run([str(ROOT / "run"), "setup"], env=env, capture_output=True, text=True, timeout=120)
    assert "to keep it, add that line to ~/.bash_profile" in p.stderr, p.stderr
