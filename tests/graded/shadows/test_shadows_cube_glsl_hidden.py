"""Hidden graded tests of the point light's GLSL route (tasks 11-12): other lights, sizes, culling and options."""

from geomlib.grading import graded

from .test_shadows_cube_glsl import check_glsl_cube_depth, check_glsl_cube_shadow


@graded(points=3, part="cube light pass", visibility="hidden", timeout=120)
def test_glsl_cube_depth_maps_hidden(lab):
    """shaders/cube_depth.vert + cube_depth.frag: a hidden light at 80² front-culled, another at 56² back-culled"""
    check_glsl_cube_depth(lab, "hidden-glsl-cube-linear-c-80-front")
    check_glsl_cube_depth(lab, "hidden-glsl-cube-linear-d-56-back")


@graded(points=2, part="cube shadow lookup", visibility="hidden", timeout=60)
def test_glsl_cube_shadow_pcf_hidden(lab):
    """shaders/cube_shadow.frag: 5 x 5 PCF on a hidden light, 3 x 3 on a back-culled map"""
    check_glsl_cube_shadow(lab, "hidden-glsl-cube-eye-pcf5")
    check_glsl_cube_shadow(lab, "hidden-glsl-cube-eye-pcf3")


@graded(points=2, part="cube shadow lookup", visibility="hidden", timeout=60)
def test_glsl_cube_shadow_defaults_hidden(lab):
    """the default bias on a hidden light"""
    check_glsl_cube_shadow(lab, "hidden-glsl-cube-eye-defaults")


@graded(points=2, part="cube light pass", visibility="hidden", timeout=120)
def test_glsl_cube_depth_maps_room_hidden(lab):
    """shaders/cube_depth.vert + cube_depth.frag from inside another room, unculled"""
    check_glsl_cube_depth(lab, "hidden-glsl-cube-linear-room2-56-none")


@graded(points=2, part="cube shadow lookup", visibility="hidden", timeout=60)
def test_glsl_cube_shadow_every_face_hidden(lab):
    """another room, unculled: lit and shadowed wall points on all six cube faces, default and small bias; face ties"""
    check_glsl_cube_shadow(lab, "hidden-glsl-cube-room-defaults")
    check_glsl_cube_shadow(lab, "hidden-glsl-cube-room-bias")
    check_glsl_cube_shadow(lab, "hidden-glsl-cube-ties-pcf3")
