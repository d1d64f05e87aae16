"""The digest the sandbox checks at every call (``_folder_digest``) is the digest of
what a snapshot copies (``_copy_lab``): were they to differ, every call would make a new snapshot."""

from __future__ import annotations

import os

from geomlib.grading import sandbox


def test_the_folder_digest_is_the_digest_of_the_copy(tmp_path):
    lab = tmp_path / "lab"
    (lab / "shaders" / "deep").mkdir(parents=True)
    (lab / "__pycache__").mkdir()
    (lab / "empty").mkdir()
    (lab / "ops.py").write_text("def f(x):\n    return x\n")
    (lab / "b.py").write_text("B = 1\n")
    (lab / "shaders" / "a.frag").write_text("void main() {}\n")
    (lab / "shaders" / "deep" / "x.glsl").write_bytes(b"\xff\xfe not utf-8")
    (lab / "__pycache__" / "ops.cpython-311.pyc").write_bytes(b"skipped")
    (lab / "link.py").symlink_to(lab / "ops.py")  # links are never followed nor copied
    (lab / "dirlink").symlink_to(lab / "shaders")
    os.mkfifo(lab / "pipe")
    dest = tmp_path / "snap" / "lab"
    dest.mkdir(parents=True)
    copied = sandbox._copy_lab(lab, dest)
    assert sandbox._folder_digest(lab) == copied
    assert sandbox._folder_digest(dest) == copied  # the snapshot holds the same names and bytes
    (lab / "shaders" / "deep" / "x.glsl").write_text("changed")
    assert sandbox._folder_digest(lab) != copied
