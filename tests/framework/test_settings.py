"""One grading run's settings, read in one place (issue 25, item 2).

- two ``check()`` calls with different implementations in one process each grade their own, write
  nothing into the environment (``GEOMLIB_IMPL`` was set with ``setdefault``: a notebook's next setup
  cell read the first one back) and keep no module-global records;
- no module reads a ``GEOMLIB_*`` variable but :mod:`geomlib.grading.settings`;
- every ``GEOMLIB_*`` variable the tooling spells (Python or the shell text of the release) is
  declared there, and docs/autograder.md lists each one once.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

from geomlib.grading.settings import VARIABLES, GradingSettings

ROOT = Path(__file__).resolve().parents[2]

_TWO_CHECKS = """
import json, os
from geomlib.grading import check, plugin
first = check("sample", impl="solutions", feedback_dir="")
second = check("sample", impl="labs", feedback_dir="")
print(json.dumps({
    "scores": [first.results["score"], second.results["score"]],
    "env": os.environ.get("GEOMLIB_IMPL"),
    "module_records": hasattr(plugin, "RECORDS"),
}))
"""


def test_two_checks_in_one_process_each_grade_their_own_impl(sample_course):
    env = {"GEOMLIB_ROOT": str(sample_course), "GEOMLIB_NO_FEEDBACK_PICTURES": "1", "PATH": "/usr/bin:/bin"}
    p = subprocess.run(
        [sys.executable, "-c", _TWO_CHECKS], cwd=sample_course, env=env, capture_output=True, text=True, timeout=600
    )
    assert p.returncode == 0, p.stderr[-3000:]
    out = json.loads(p.stdout.strip().splitlines()[-1])
    assert out["scores"] == [7, 0], out
    assert out["env"] is None, "check() wrote GEOMLIB_IMPL into the environment: the next setup cell reads it back"
    assert out["module_records"] is False, "records belong to the run's GradingRun plugin, not to a module global"


def test_settings_are_built_from_the_caller_then_the_environment(monkeypatch):
    monkeypatch.setenv("GEOMLIB_TIME_BUDGET", "12")
    monkeypatch.setenv("GEOMLIB_MAX_FEEDBACK_PICTURES", "3")
    monkeypatch.delenv("GEOMLIB_NO_FEEDBACK_PICTURES", raising=False)
    s = GradingSettings.build(impl="labs", time_budget=None)
    assert (s.impl, s.time_budget, s.max_pictures, s.pictures) == ("labs", 12.0, 3, True)
    assert GradingSettings.build(time_budget=5).time_budget == 5
    monkeypatch.setenv("GEOMLIB_NO_FEEDBACK_PICTURES", "1")
    assert GradingSettings.build().pictures is False


#: Reading a GEOMLIB_ variable: os.environ.get("GEOMLIB_..."), os.environ["GEOMLIB_..."] (not assigned), getenv.
_READ = re.compile(
    r"""(?:environ\.get|getenv|environ\.setdefault)\(\s*[fr]?["']GEOMLIB_|environ\[\s*["']GEOMLIB_\w*["']\s*\](?!\s*=[^=])"""
)
#: bootstrap.py runs before any environment exists and imports nothing from geomlib.
_READERS = {"geomlib/grading/settings.py", "geomlib/grading/bootstrap.py"}


def test_no_module_reads_a_geomlib_variable_but_the_settings():
    files = [*ROOT.joinpath("geomlib").rglob("*.py"), *ROOT.joinpath("solutions").rglob("*.py")]
    bad = [
        f"{f.relative_to(ROOT)}:{i}: {line.strip()}"
        for f in files
        if str(f.relative_to(ROOT)) not in _READERS
        for i, line in enumerate(f.read_text().splitlines(), 1)
        if _READ.search(line)
    ]
    assert not bad, "read GEOMLIB_* variables through geomlib.grading.settings:\n" + "\n".join(bad)


def test_every_variable_is_declared_and_documented_once():
    spelled = set()
    for f in ROOT.joinpath("geomlib").rglob("*"):
        if f.suffix in (".py", ".sh"):
            spelled |= set(re.findall(r"GEOMLIB_[A-Z][A-Z0-9_]*[A-Z0-9]", f.read_text()))
    spelled.discard("GEOMLIB_IMPL")  # the notebooks' own variable (their setup cell), not the tooling's
    assert sorted(spelled - set(VARIABLES)) == [], "declare these in geomlib.grading.settings.VARIABLES"
    doc = (ROOT / "docs" / "autograder.md").read_text()
    rows = re.findall(r"^\| `(GEOMLIB_\w+)` \|", doc, flags=re.M)
    assert sorted(rows) == sorted(VARIABLES), (
        "docs/autograder.md: one table row per variable (settings.markdown_table())"
    )


def test_the_picture_time_limit_is_one_run_setting(monkeypatch, tmp_path):
    """``GEOMLIB_PICTURE_TIME_LIMIT`` (default ``tolerances.PICTURE_TIME_S``) is the limit a feedback
    picture is drawn under; the suite raises it for its loaded machine the same way (root conftest.py)
    instead of patching the module constant in every process."""
    import time

    from geomlib.grading import picture_run, tolerances

    monkeypatch.delenv("GEOMLIB_PICTURE_TIME_LIMIT", raising=False)
    monkeypatch.delenv("GEOMLIB_NO_FEEDBACK_PICTURES", raising=False)
    monkeypatch.delenv("GEOMLIB_MAX_FEEDBACK_PICTURES", raising=False)
    assert GradingSettings.build().picture_time_limit == tolerances.PICTURE_TIME_S
    monkeypatch.setenv("GEOMLIB_PICTURE_TIME_LIMIT", "0.5")
    assert GradingSettings.build().picture_time_limit == 0.5
    path = tmp_path / "slow.png"

    def slow_draw():
        time.sleep(3)
        path.write_bytes(b"drawn")

    t = time.monotonic()
    assert picture_run._drawn_in_time(str(path), slow_draw) is None  # given up after the run's limit
    assert time.monotonic() - t < 2.5 and not path.exists()
