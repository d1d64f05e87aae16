"""Graded tests of the lab "subdivision"."""

#: What the subdivision lab's code may not call (the grader makes each raise in student code; the handout
#: lists them under "Not allowed"): name -> why. See geomlib.grading.blacklist.
NOT_ALLOWED = {
    "igl.loop": "it subdivides for you (Tasks 1-5 ask you to write Loop subdivision)",
    "igl.loop_matrix": "Tasks 1 and 2 ask you to build the subdivision matrices",
    "igl.upsample": "Task 3 asks you to write the connectivity",
    "igl.upsample_matrix": "Task 3 asks you to write the connectivity",
    "trimesh.remesh.subdivide_loop": "it subdivides for you (Tasks 1-5 ask you to write Loop subdivision)",
    "trimesh.remesh.subdivide": "Task 3 asks you to write the connectivity",
    "pyvista.PolyData.subdivide": "it subdivides for you (Tasks 1-9)",
    "pyvista.PolyData.subdivide_adaptive": "it subdivides for you (Tasks 1-9)",
    "vtkmodules.vtkFiltersModeling.vtkLoopSubdivisionFilter": "it subdivides for you (Tasks 1-5)",
    "vtkmodules.vtkFiltersModeling.vtkLinearSubdivisionFilter": "Task 3 asks you to write the connectivity",
    "vtkmodules.vtkFiltersModeling.vtkButterflySubdivisionFilter": "it subdivides for you (Tasks 1-5)",
}
