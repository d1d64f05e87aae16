"""Graded tests of the denoise lab (Laplacian displacement denoising)."""

#: What the denoise lab's code may not call (the grader makes each raise in student code; the handout
#: lists them under "Not allowed"): name -> why. See geomlib.grading.blacklist.
NOT_ALLOWED = {
    "trimesh.smoothing.filter_laplacian": "Task 3 asks you to write the denoising",
    "trimesh.smoothing.filter_taubin": "Task 3 asks you to write the denoising",
    "trimesh.smoothing.filter_humphrey": "Task 3 asks you to write the denoising",
    "trimesh.smoothing.filter_mut_dif_laplacian": "Task 3 asks you to write the denoising",
    "pyvista.PolyData.smooth": "Task 3 asks you to write the denoising",
    "pyvista.PolyData.smooth_taubin": "Task 3 asks you to write the denoising",
    "igl.per_vertex_attribute_smoothing": "Task 3 asks you to write the denoising",
}
