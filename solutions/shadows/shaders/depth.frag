#version 330 core
// Task 9 in GLSL, fragment stage of the light pass (see depth_map and cull_faces in depth.py). The GPU's
// depth test keeps the fragment nearest to the light in every texel; what this stage writes there is the
// shadow map: result.r = window depth in [0, 1], result.g = 1 (the texel is covered; the given code sets
// the texels nothing covers to 1.0, the far plane).

uniform int cull;  // 0: keep every face; 1: drop front faces (cull = "front"); 2: drop back faces ("back")

out vec4 result;

void main() {
    // BEGIN SOLUTION: Task 9 (light pass): discard front faces (gl_FrontFacing: counter-clockwise on screen) for cull = 1, back faces for cull = 2; result = (gl_FragCoord.z, 1, 0, 1)
    if ((cull == 1 && gl_FrontFacing) || (cull == 2 && !gl_FrontFacing)) {
        discard;
    }
    result = vec4(gl_FragCoord.z, 1.0, 0.0, 1.0);
    // END SOLUTION
}
