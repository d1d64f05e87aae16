"""Graded tests of the remeshing lab."""
