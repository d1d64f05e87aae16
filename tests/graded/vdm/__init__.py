"""Graded tests of the lab "vdm" (vector displacement map baking)."""
