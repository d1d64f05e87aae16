#version 330 core
// Task 7 in GLSL: the TBN frame of a vertex in world space (see surface_frames in geomlib.tangent_space).
// One vertex per point; the given main() writes T, B, N of vertex gl_VertexID to three float targets.

in vec3 normal;     // object-space vertex normal (any length)
in vec4 tangent;    // object-space [T, w]: tangent and handedness sign w = +-1 (w < 0: mirrored UVs)
uniform mat4 model; // object -> world (normals go through the inverse transpose of its 3x3 part)
uniform ivec2 grid;  // given: the read-back image's size (vertex i -> pixel (i % width, i / width))

flat out vec3 T_world;
flat out vec3 B_world;
flat out vec3 N_world;

void tbn(vec3 n, vec4 t, out vec3 T, out vec3 B, out vec3 N) {
    // BEGIN SOLUTION: Task 7 (vertex TBN): N = normalize(inverse transpose(model) n), T = normalize(model t.xyz) made orthogonal to N, B = sign(w) N x T (w = 0 counts as +1)
    mat3 m = mat3(model);
    N = normalize(transpose(inverse(m)) * n);
    vec3 t_world = m * t.xyz;
    T = normalize(t_world - dot(t_world, N) * N);
    B = (t.w < 0.0 ? -1.0 : 1.0) * cross(N, T);
    // END SOLUTION
}

// Given: vertex i becomes one point at pixel (i % width, i / width) of the read-back image.
vec4 point_position(int i) {
    vec2 pixel = vec2(float(i % grid.x), float(i / grid.x)) + 0.5;
    return vec4(pixel * 2.0 / vec2(grid) - 1.0, 0.0, 1.0);
}

void main() {
    tbn(normal, tangent, T_world, B_world, N_world);
    gl_Position = point_position(gl_VertexID);
    gl_PointSize = 1.0;
}
