"""Benchmarks: each lab's reference solution timed next to the anchor libraries, in one run.

Run one from the project's environment, e.g. ``uv run python bench/maps.py --quick``. That
environment's editable install puts the project root on ``sys.path``, which is how the scripts
import ``solutions`` and this package's shared pieces: :mod:`bench.measure` (timing, peak memory,
the shared meshes folder) and :mod:`bench.anchors` (anchor-library set-ups that the solution
cross-checks in ``tests/solutions`` use too; pytest's ``pythonpath`` makes them importable there).
"""
