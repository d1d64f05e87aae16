"""Graded tests of the lab "simplification"."""

#: What the simplification lab's code may not call (the grader makes each raise in student code; the handout
#: lists them under "Not allowed"): name -> why. See geomlib.grading.blacklist.
NOT_ALLOWED = {
    "igl.qslim": "it simplifies for you (Tasks 1-4 ask you to write quadric simplification)",
    "igl.decimate": "it simplifies for you (Tasks 1-4 ask you to write quadric simplification)",
    "igl.collapse_edge": "Task 3 asks you to write the contraction",
    "fast_simplification.simplify": "it simplifies for you (Tasks 1-4 ask you to write quadric simplification)",
    "fast_simplification.simplify_mesh": "it simplifies for you (Tasks 1-4 ask you to write quadric simplification)",
    "pyvista.PolyData.decimate": "it simplifies for you (Tasks 1-4 ask you to write quadric simplification)",
    "pyvista.PolyData.decimate_pro": "it simplifies for you (Tasks 1-4 ask you to write quadric simplification)",
    "vtkmodules.vtkFiltersCore.vtkQuadricDecimation": "it simplifies for you (Tasks 1-4 ask you to write quadric simplification)",
    "vtkmodules.vtkFiltersCore.vtkDecimatePro": "it simplifies for you (Tasks 1-4 ask you to write quadric simplification)",
}
