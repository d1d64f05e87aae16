#version 330 core
// Task 11 in GLSL, fragment stage of a point light's cube pass. The depth test keeps the surface nearest to the
// light in every texel of the face; what this stage writes there is the face's map in *linear* depth:
// result.r = |world - lightPos| / far (the distance to the light as a fraction of the far distance, not the
// window depth gl_FragCoord.z), result.g = 1 (the texel is covered; the given code fills the others).

in vec3 world;          // world position of the fragment (from cube_depth.vert)
uniform vec3 lightPos;  // the point light
uniform float far;      // the far distance of the cube's faces
uniform int cull;       // 0: keep every face; 1: drop front faces (cull = "front"); 2: drop back faces ("back")

out vec4 result;

void main() {
    // BEGIN SOLUTION: Task 11 (cube light pass): discard culled faces by gl_FrontFacing as in depth.frag; result = (length(world - lightPos) / far, 1, 0, 1)
    if ((cull == 1 && gl_FrontFacing) || (cull == 2 && !gl_FrontFacing)) {
        discard;
    }
    result = vec4(length(world - lightPos) / far, 1.0, 0.0, 1.0);
    // END SOLUTION
}
