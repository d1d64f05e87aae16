"""Graded tests of the lab "maps" (normal maps and displacement maps)."""
