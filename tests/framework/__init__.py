"""Tests of the grading framework itself."""
