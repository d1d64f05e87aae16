"""Graded tests: one folder per lab, run against any implementation (--impl).

Each lab's ``test_<lab>.py`` has two kinds of test: ``test_references`` compares with the stored
reference outputs of ``cases.py`` on realistic meshes; the others use tiny inputs whose answers are
worked out by hand in their docstrings and comments, identities any correct implementation
satisfies, and bad input. Expected values never come from running a solution at test time.
"""
