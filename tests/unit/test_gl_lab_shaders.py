"""One way for every lab to find and read its GLSL files (issue 25): ``geomlib.gl.shader_finder``
(each GLSL lab's ``shader_path``), ``lab_shader_source`` (a stub's ``#error Task N`` becomes
``NotImplementedError``) and ``naming_task`` (a compile error names the file and its task)."""

from __future__ import annotations

import importlib
from pathlib import Path

import pytest

from geomlib import gl
from geomlib.grading.course import course

ROOT = Path(__file__).resolve().parents[2]
GLSL_LABS = [n for n in course(ROOT).solution_labs if (course(ROOT).lab(n).solution / gl.SHADER_FOLDER).is_dir()]


def test_the_glsl_labs_are_found():
    assert {"relief", "maps", "denoise"} <= set(GLSL_LABS)


@pytest.mark.parametrize("lab", GLSL_LABS)
@pytest.mark.parametrize("package", ["solutions", "labs"])
def test_every_glsl_lab_finds_its_shaders_with_the_one_helper(lab, package):
    """No lab writes its own ``shader_path``: each is ``gl.shader_finder(__file__)``, and it finds every
    shader file of the lab by file name and by stem, in the lab's own folder (solutions or stubs)."""
    glsl = importlib.import_module(f"{package}.{lab}.glsl")
    assert glsl.shader_path.__qualname__ == "shader_finder.<locals>.shader_path", f"{lab}: use gl.shader_finder"
    folder = Path(glsl.__file__).resolve().parent / gl.SHADER_FOLDER
    files = sorted(p for p in folder.iterdir() if p.suffix in (".vert", ".frag"))
    assert files
    for f in files:
        assert glsl.shader_path(f.name) == f
        if [g.stem for g in files].count(f.stem) == 1:  # shadows has depth.vert and depth.frag
            assert glsl.shader_path(f.stem) == f


def test_shader_finder_takes_the_folder_or_a_file_in_it_and_names_what_is_there(tmp_path):
    (tmp_path / "shaders").mkdir()
    (tmp_path / "shaders" / "a.frag").write_text("")
    (tmp_path / "shaders" / "b.vert").write_text("")
    (tmp_path / "shaders" / "b.frag").write_text("")
    by_file = gl.shader_finder(tmp_path / "glsl.py")
    assert gl.shader_finder(tmp_path)("a") == by_file("a") == tmp_path / "shaders" / "a.frag"
    assert by_file("b.vert") == tmp_path / "shaders" / "b.vert"
    with pytest.raises(FileNotFoundError, match=r"2 shader file\(s\) named 'b'.*a.frag, b.frag, b.vert"):
        by_file("b")
    with pytest.raises(FileNotFoundError, match="no shader file"):
        by_file("c")


def test_an_unfilled_shader_is_not_implemented_and_a_filled_one_is_read(tmp_path):
    stub = tmp_path / "relief.frag"
    stub.write_text("#version 330 core\n#error Task 3 (march): find the first layer below\nvoid main() {}\n")
    with pytest.raises(NotImplementedError, match=r"^shaders/relief.frag: Task 3 \(march\): find the first"):
        gl.lab_shader_source(stub)
    done = tmp_path / "parallax.frag"
    done.write_text("#version 330 core\nvoid main() {}\n")
    assert gl.lab_shader_source(done) == done.read_text()


def test_a_compile_error_names_the_file_and_its_task():
    with pytest.raises(gl.ShaderError) as info, gl.naming_task("shaders/x.frag", "Task 2: parallax"):
        raise gl.ShaderError("shaders/x.frag: line 3: syntax error", log="0:3(1): error", lines=(3,))
    assert str(info.value) == "shaders/x.frag (Task 2: parallax): line 3: syntax error"
    assert info.value.log == "0:3(1): error" and info.value.lines == (3,)
    with gl.naming_task("shaders/x.frag", "Task 2"):
        pass  # nothing raised: nothing changed
