"""Graded tests of the lab "shadows" (shadow mapping)."""
