#!/usr/bin/env bash
# The one set-up script of a grading machine, as root: Gradescope's autograder image (`geomlib
# release` puts this file, with the lab's name, at the top of autograder-<lab>.zip) and the dev
# container's image (.devcontainer/Dockerfile runs it on the course copied to /opt/geomlib/source).
# Locally (as root):  GEOMLIB_AUTOGRADER_ROOT=/tmp/ag bash /tmp/ag/source/setup.sh
# It installs the grader where the sandbox user (GEOMLIB_SANDBOX_USER, default nobody) can run it
# and makes the hidden cases and references readable by root only. GEOMLIB_SETUP_DEV=1 also
# installs the students' tools (JupyterLab, the dev group of pyproject.toml): the dev container.
set -euo pipefail
LAB="@LAB@"  # geomlib release writes the lab's name here
case "$LAB" in *@) LAB="the course" ;; esac
ROOT="${GEOMLIB_AUTOGRADER_ROOT:-/autograder}"
SRC="$ROOT/source"
SANDBOX_USER="${GEOMLIB_SANDBOX_USER-nobody}"
cd "$SRC"
export DEBIAN_FRONTEND=noninteractive
# runuser and ldconfig live in sbin, which a minimal PATH (env -i, cron, some images) leaves out.
export PATH="$PATH:/usr/sbin:/sbin"

# System packages, only the missing ones: headless OpenGL (OSMesa for pyrender and the GLSL
# harness; EGL with Mesa's software driver as the fallback platform), a Python 3 (for uv's bootstrap).
need=()
ldconfig -p 2>/dev/null | grep -q 'libOSMesa\.so' || need+=(libosmesa6)
# libGL and libXrender too: pyrender imports pyglet's viewer, which loads both even to render off
# screen (a Debian 12 root with the OSMesa/EGL packages only: `import pyrender` -> 'Library "GL" not
# found', then "'NoneType' object has no attribute 'XRenderFindVisualFormat'").
ldconfig -p 2>/dev/null | grep -q 'libGL\.so\.1' || need+=(libgl1)
ldconfig -p 2>/dev/null | grep -q 'libXrender\.so\.1' || need+=(libxrender1)
ldconfig -p 2>/dev/null | grep -q 'libEGL\.so' || need+=(libegl1)
ldconfig -p 2>/dev/null | grep -q 'libEGL_mesa\.so' || need+=(libegl-mesa0)
compgen -G "${GEOMLIB_DRI_DIR:-/usr/lib/*/dri}/swrast_dri.so" >/dev/null || need+=(libgl1-mesa-dri)
command -v python3 >/dev/null 2>&1 || need+=(python3)
[ -e /etc/ssl/certs/ca-certificates.crt ] || need+=(ca-certificates)  # uv and its bootstrap reach PyPI over TLS
if [ ${#need[@]} -gt 0 ]; then
  echo "setup.sh: apt-get install ${need[*]}"
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${need[@]}" >/dev/null
fi
# uv as ./run gets it (geomlib/grading/bootstrap.py: the one on the PATH, else its pinned PyPI wheel,
# sha256 checked, unpacked into root's home): never pip into the system Python (PEP 668).
UV="$(python3 "$SRC/geomlib/grading/bootstrap.py" uv)"
# uv reaches PyPI with the system's certificate store too, as under ./run: a TLS-intercepting proxy's
# CA (a campus or company network building the dev container) is installed there, and uv's own
# bundled roots do not have it (measured: a Debian 12 root behind such a proxy failed here with
# "invalid peer certificate: UnknownIssuer" while the bootstrap's download, which uses the system
# store, had worked).
export UV_SYSTEM_CERTS="${UV_SYSTEM_CERTS-1}"
uv() { "$UV" "$@"; }

# A Python the sandbox user can read (not one under /root, which it cannot open): the one named by
# GEOMLIB_AUTOGRADER_PYTHON, else a system python3.11, else uv installs 3.11 under $ROOT/python.
PY="${GEOMLIB_AUTOGRADER_PYTHON:-}"
for cand in /usr/bin/python3.11 /usr/local/bin/python3.11; do
  if [ -n "$PY" ]; then break; fi
  if [ -x "$cand" ]; then PY="$cand"; break; fi
done
if [ -z "$PY" ]; then
  export UV_PYTHON_INSTALL_DIR="$ROOT/python"
  uv python install 3.11
  chmod -R a+rX "$ROOT/python"
  PY="$(uv python find 3.11)"
fi
echo "setup.sh: Python $PY"

# The locked library and the test runner (no dev tools) in source/.venv, with bytecode compiled now
# (the sandbox user cannot write it).
export UV_PROJECT_ENVIRONMENT="$SRC/.venv"
if [ "${GEOMLIB_SETUP_DEV:-}" = 1 ]; then groups=(); else groups=(--no-dev --group grading); fi
uv sync --frozen "${groups[@]}" --compile-bytecode --python "$PY" --no-python-downloads --quiet
chmod a+rx "$ROOT"
chmod -R a+rX "$SRC"
# Hidden cases, hidden tests and hidden references: root only.
find "$SRC/tests" -name '*hidden*' -exec chmod -R go-rwx {} +

# The grader must start, and the sandbox user must be able to run the same Python.
"$SRC/.venv/bin/python" -c 'import geomlib.grading.grade, pytest, numpy, scipy'
if [ "$(id -u)" = 0 ] && [ -n "$SANDBOX_USER" ]; then
  if ! (cd / && runuser -u "$SANDBOX_USER" -- "$SRC/.venv/bin/python" -c 'import numpy, scipy, geomlib.grading.worker'); then
    echo "setup.sh: the sandbox user '$SANDBOX_USER' cannot run $SRC/.venv/bin/python (check the permissions of $ROOT and of the Python)" >&2
    exit 1
  fi
fi
echo "setup.sh: ready to grade $LAB"
