"""Finding a lab in a submission and copying it without trusting it.

A submission is a folder that holds the lab folder either directly (``subdivision/``) or inside a
checkout (``labs/subdivision/``), possibly one level down (Gradescope keeps the folder name of an
uploaded zip, e.g. ``my-work/labs/subdivision/``). Grading never reads the submission in place:
:func:`copy_lab` copies its regular files into a private folder, skipping symbolic links (a link
could point into the course, at hidden material or at another submission), devices, FIFOs and
anything too large.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

__all__ = ["find_lab", "copy_lab", "SubmissionError", "MAX_FILE_BYTES", "MAX_TOTAL_BYTES"]

#: A lab folder's files are code and small data; anything bigger is not copied.
MAX_FILE_BYTES = 20 * 2**20
MAX_TOTAL_BYTES = 200 * 2**20
_SKIP_DIRS = {"__pycache__", ".git", ".ipynb_checkpoints", ".pytest_cache", ".venv", "node_modules"}


class SubmissionError(ValueError):
    """The submission does not contain the lab (the message says what it does contain)."""


def _is_real_dir(p: Path) -> bool:
    try:
        return stat.S_ISDIR(os.lstat(p).st_mode)
    except OSError:
        return False


def find_lab(submission: str | os.PathLike, lab: str) -> Path:
    """The folder of ``lab`` inside ``submission`` (``<lab>/``, ``labs/<lab>/``, one level deeper too).

    Symbolic links are never followed, so a link named ``labs`` or ``<lab>`` does not count.

    Raises
    ------
    SubmissionError
        When no such folder exists; the message lists what the submission's top level holds.
    """
    sub = Path(submission)
    if not _is_real_dir(sub):
        raise SubmissionError(f"submission folder {sub} does not exist")
    tops = [sub]
    try:
        children = sorted(p for p in sub.iterdir() if _is_real_dir(p) and p.name not in _SKIP_DIRS)
    except OSError:
        children = []
    from geomlib.grading.course import course

    labs = course().stubs_dir.name  # a student's checkout holds the lab in labs/<lab>/
    tops += [c for c in children if c.name not in (lab, labs)]
    for top in tops:
        for cand in (top / lab, top / labs / lab):
            if _is_real_dir(cand.parent) and _is_real_dir(cand):
                return cand
    try:
        found = sorted(p.name + ("/" if _is_real_dir(p) else "") for p in sub.iterdir())[:12]
    except OSError:
        found = []
    raise SubmissionError(
        f"the submission has no folder {lab}/ or labs/{lab}/ (it holds: {', '.join(found) or 'nothing'}); "
        f"upload the lab folder itself or your checkout's labs/ folder"
    )


def copy_lab(src: str | os.PathLike, dest: str | os.PathLike) -> list[str]:
    """Copy the regular files under ``src`` to ``dest`` without following any link; returns what was skipped.

    ``dest`` must not exist. Files and folders get the modes ``0644``/``0755`` (readable by the
    sandbox user, whatever the submission's own modes were).
    """
    src, dest = Path(src), Path(dest)
    skipped: list[str] = []
    total = 0
    dest.mkdir(parents=True, exist_ok=False)
    os.chmod(dest, 0o755)
    for dirpath, dirnames, filenames in os.walk(src, followlinks=False):
        here = Path(dirpath)
        rel_dir = here.relative_to(src)
        keep = []
        for d in sorted(dirnames):
            p = here / d
            if d in _SKIP_DIRS:
                continue
            if not _is_real_dir(p):  # a symbolic link to a folder
                skipped.append(f"{(rel_dir / d).as_posix()} (symbolic link)")
                continue
            keep.append(d)
            (dest / rel_dir / d).mkdir()
            os.chmod(dest / rel_dir / d, 0o755)
        dirnames[:] = keep
        for name in sorted(filenames):
            p, rel = here / name, (rel_dir / name).as_posix()
            try:
                st = os.lstat(p)
            except OSError:
                continue
            if not stat.S_ISREG(st.st_mode):
                skipped.append(f"{rel} ({'symbolic link' if stat.S_ISLNK(st.st_mode) else 'not a regular file'})")
                continue
            if st.st_size > MAX_FILE_BYTES or total + st.st_size > MAX_TOTAL_BYTES:
                skipped.append(f"{rel} (too large: {st.st_size} bytes)")
                continue
            # O_NOFOLLOW: the file cannot be swapped for a link between the lstat and the open.
            fd = os.open(p, os.O_RDONLY | os.O_NOFOLLOW)
            with os.fdopen(fd, "rb") as f:
                data = f.read(MAX_FILE_BYTES + 1)
            target = dest / rel_dir / name
            with open(target, "xb") as f:
                f.write(data)
            os.chmod(target, 0o644)
            total += len(data)
    return skipped


def main(argv: list[str] | None = None) -> int:
    """``python -m geomlib.grading.submission SUBMISSION LAB DEST [--results FILE]``.

    Copies the lab into ``DEST/LAB`` and prints what was not copied. When the submission has no
    such lab it exits with status 3 and, with ``--results``, writes a ``results.json`` that tells
    the student what was expected.
    """
    import argparse
    import json

    ap = argparse.ArgumentParser(prog="python -m geomlib.grading.submission")
    ap.add_argument("submission")
    ap.add_argument("lab")
    ap.add_argument("dest")
    ap.add_argument("--results")
    a = ap.parse_args(argv)
    try:
        folder = find_lab(a.submission, a.lab)
    except SubmissionError as e:
        print(e)
        if a.results:
            data = {
                "score": 0,
                "output": f"Nothing was graded: {e}.",
                "output_format": "text",
                "visibility": "visible",
                "stdout_visibility": "hidden",
                "tests": [],
            }
            Path(a.results).write_text(json.dumps(data, indent=1) + "\n")
        return 3
    for s in copy_lab(folder, Path(a.dest) / a.lab):
        print(f"not copied: {s}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
