"""Graded tests of the lab "relief"."""
