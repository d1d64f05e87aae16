#version 330 core
// Task 9 in GLSL, vertex stage of the light pass (see depth_map in depth.py): every vertex of the scene
// is seen from the light. One draw of the whole scene; the fragment stage (depth.frag) stores the depth.

in vec3 position;               // world position of the vertex
uniform mat4 lightSpaceMatrix;  // clip from world: projection @ look_at of the light (Task 1's M)

void main() {
    #error Task 9 (light pass): gl_Position = lightSpaceMatrix * (position, 1): clip coordinates as seen from the light
}
