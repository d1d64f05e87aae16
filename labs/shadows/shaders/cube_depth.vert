#version 330 core
// Task 11 in GLSL, vertex stage of a point light's cube pass (see cube_depth_maps and cube_distance_maps in
// cubemap.py and cube_glsl.py): the scene is drawn six times, once per cube face, each time through that face's
// 90-degree camera. The fragment stage (cube_depth.frag) needs the world position of every fragment.

in vec3 position;               // world position of the vertex
uniform mat4 lightSpaceMatrix;  // clip from world of this face: perspective(90, 1, near, far) @ look_at (Task 8's Ms[i])

out vec3 world;                 // the vertex's world position, interpolated for cube_depth.frag

void main() {
    #error Task 11 (cube light pass): gl_Position = lightSpaceMatrix * (position, 1); pass the world position on in `world`
}
