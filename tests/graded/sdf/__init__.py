"""Graded tests of the lab "sdf"."""

#: What the sdf lab's code may not call (the grader makes each raise in student code; the handout
#: lists them under "Not allowed"): name -> why. See geomlib.grading.blacklist.
NOT_ALLOWED = {
    "igl.signed_distance": "Task 4 asks you to write it",
    "igl.winding_number": "Task 4 asks you to write it",
    "igl.fast_winding_number": "Task 4 asks you to write it",
    "igl.pseudonormal_test": "Task 4 asks you to write it",
    "igl.point_mesh_squared_distance": "Tasks 2 and 3 ask you to write it",
    "igl.point_simplex_squared_distance": "Task 2 asks you to write it",
    "igl.AABB.squared_distance": "Task 3 asks you to write it",
    "igl.ambient_occlusion": "Task 9 asks you to write it",
    "igl.embree.ambient_occlusion": "Task 9 asks you to write it",
    "trimesh.proximity.signed_distance": "Task 4 asks you to write it",
    "trimesh.proximity.closest_point": "Tasks 2 and 3 ask you to write it",
    "geomlib.geometry.closest_points": "Tasks 2 and 3 ask you to write it (it is libigl's AABB tree)",
    "geomlib.geometry.ray_cast": "Task 4 asks you to count the ray crossings yourself",
    "scipy.ndimage.map_coordinates": "Task 6 asks you to write the trilinear interpolation",
}
