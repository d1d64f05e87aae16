"""Graded tests of the remeshing lab."""

#: What the remeshing lab's code may not call (the grader makes each raise in student code; the handout
#: lists them under "Not allowed"): name -> why. See geomlib.grading.blacklist.
NOT_ALLOWED = {
    "igl.collapse_edge": "Task 2 asks you to write the edge collapse",
    "trimesh.remesh.subdivide_to_size": "Task 4 asks you to split long edges",
    "pyvista.PolyData.subdivide_adaptive": "Task 4 asks you to split long edges",
    "pyvista.PolyData.decimate": "Task 5 asks you to collapse short edges",
    "fast_simplification.simplify": "Task 5 asks you to collapse short edges",
}
