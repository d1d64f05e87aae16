"""Test-suite wiring: the grading plugin (``--impl``, the ``lab`` fixture, scores)."""

pytest_plugins = ["geomlib.grading.plugin"]
