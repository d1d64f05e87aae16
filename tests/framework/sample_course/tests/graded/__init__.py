"""Graded tests."""
