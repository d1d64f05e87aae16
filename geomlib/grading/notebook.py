"""The first cell of every lab notebook: ``lab, tasks_done = open_lab("subdivision")``.

A notebook runs on whatever is implemented: the reference solution where it is present
(instructors), else the student's ``labs/<lab>``; ``GEOMLIB_IMPL`` chooses another. A cell that
needs a task not done yet is wrapped in ``with tasks_done():`` and says so ("Task 2 not implemented
yet (even vertices): the rest of this cell is skipped"); the notebook goes on.
"""

from __future__ import annotations

import contextlib
from types import ModuleType

from geomlib.taskref import find_task

__all__ = ["open_lab", "TasksDone"]


class TasksDone:
    """``with tasks_done():`` around a cell: a task not implemented yet ends the cell with one line
    naming the task, not a traceback; a name a skipped cell above should have defined is reported as
    such. Any other error (in a lab function, or once every task is done) is raised as usual."""

    def __init__(self):
        #: Tasks whose absence skipped a cell so far ("Task 2", ...).
        self.missing: list[str] = []

    @contextlib.contextmanager
    def __call__(self):
        try:
            yield
        except NotImplementedError as e:
            m = find_task(str(e))
            task = f"Task {m.label}" if m else "a task"
            self.missing.append(task)
            title = f" ({m.title})" if m and m.title else ""
            print(f"{task} not implemented yet{title}: the rest of this cell is skipped")
        except NameError as e:
            tb = e.__traceback__
            while tb.tb_next is not None:
                tb = tb.tb_next
            where = tb.tb_frame.f_code.co_filename
            if not self.missing or not ("ipykernel" in where or where.startswith("<")):
                raise  # a real mistake: in a lab function, or in a notebook whose tasks are all done
            needs = ", ".join(sorted(set(self.missing)))
            print(f"skipped: this cell needs {e.name!r} from a cell above, which needs {needs}")


def open_lab(lab: str, impl: str | None = None) -> tuple[ModuleType, TasksDone]:
    """The lab's package to call in the notebook, and its ``tasks_done`` guard for cells.

    Parameters
    ----------
    lab : str
        The lab's name (``"subdivision"``).
    impl : str, optional
        ``"solutions"``, ``"labs"`` or a folder; default ``GEOMLIB_IMPL``, else the solutions where
        present, else ``labs``.
    """
    from geomlib.grading.impl import default_impl, load_lab
    from geomlib.grading.settings import env

    impl = impl or env("GEOMLIB_IMPL") or default_impl()
    module = load_lab(lab, impl)
    print(f"using the {impl} implementation: {module.__name__}")
    return module, TasksDone()
