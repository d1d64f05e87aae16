"""Graded tests of the lab "vdm" (vector displacement map baking)."""

#: What the vdm lab's code may not call (the grader makes each raise in student code; the handout
#: lists them under "Not allowed"): name -> why. See geomlib.grading.blacklist.
NOT_ALLOWED = {
    "igl.map_vertices_to_circle": "Task 1a asks you to map the boundary to the square yourself",
    "matplotlib.tri.Triangulation.get_trifinder": "Task 2a asks you to locate the points yourself",
    "ot.emd": "Task 6a asks you to write the transport solver (POT is the cross-check)",
    "ot.emd2": "Task 6a asks you to write the transport solver (POT is the cross-check)",
    "ot.sinkhorn": "Task 6a asks you to write the transport solver (POT is the cross-check)",
    "ot.sinkhorn2": "Task 6a asks you to write the transport solver (POT is the cross-check)",
    "ot.solve": "Task 6a asks you to write the transport solver (POT is the cross-check)",
}
