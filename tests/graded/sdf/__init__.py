"""Graded tests of the lab "sdf"."""
