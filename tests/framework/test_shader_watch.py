"""The note of the running shader (geomlib.grading.shader_watch) is read as untrusted input (issue 23, item 4)."""

from __future__ import annotations

import os
from pathlib import Path

from geomlib.grading import shader_watch

COURSE = Path(__file__).resolve().parents[2]


def test_the_note_names_the_running_shader_and_goes_away_when_it_is_done(tmp_path):
    import geomlib.gl

    before = geomlib.gl.on_shader
    try:
        shader_watch.install(str(tmp_path))
        geomlib.gl._note_shader("shaders/relief.frag")
        assert shader_watch.read(str(tmp_path)) == "shaders/relief.frag"
        geomlib.gl._note_shader(None)
        assert shader_watch.read(str(tmp_path)) is None
    finally:
        geomlib.gl.on_shader = before


def test_a_forged_note_is_ignored(tmp_path):
    note = tmp_path / shader_watch.NOTE
    note.symlink_to("/etc/passwd")
    assert shader_watch.read(str(tmp_path)) is None
    note.unlink()
    os.mkfifo(note)
    assert shader_watch.read(str(tmp_path)) is None  # and does not block
    note.unlink()
    for bad in ("../../etc/shadow.frag", "x" * 500 + ".frag", "notes.txt", "a\nb.frag"):
        note.write_text(bad)
        assert shader_watch.read(str(tmp_path)) is None, bad


def test_the_message_takes_the_task_from_the_course_stub():
    msg = shader_watch.timeout_message("glsl_relief_shadow", 60, "shaders/shadow.frag", [COURSE / "labs" / "relief"])
    assert "shaders/shadow.frag (Task 4 (shadow))" in msg
    assert "a loop that does not end or a very long one" in msg
