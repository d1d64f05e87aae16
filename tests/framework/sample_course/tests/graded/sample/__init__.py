"""Sample lab graded tests."""
