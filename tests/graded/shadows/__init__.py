"""Graded tests of the lab "shadows" (shadow mapping)."""

#: What the shadows lab's code may not call (the grader makes each raise in student code; the handout
#: lists them under "Not allowed"): name -> why. See geomlib.grading.blacklist.
NOT_ALLOWED = {
    "geomlib.geometry.ray_cast": "it is the oracle that checks your shadow maps (Tasks 2-8)",
    "pyrender.OffscreenRenderer.render": "pyrender's shadow maps are what the tests compare you with",
}
