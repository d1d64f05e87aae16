#version 330 core
// Task 12 in GLSL: a point light's shadow test through its cube map, one surface point per fragment (see
// linear_point_shadow_visibility in cube_glsl.py). The six faces' maps hold *linear* depth, the distance to
// the light over far (cube_depth.frag), side by side in one texture: face i is columns i size .. (i + 1) size - 1.
// Output: result = (visibility in [0, 1], 0, 0, 1).

uniform sampler2D position_in;  // world position P of the point
uniform sampler2D cube_maps;    // the six faces' linear depths, size x 6 size (row 0 = the top of every face)
uniform vec3 lightPos;          // the point light
uniform float far;              // the faces' far distance
uniform float bias;             // constant bias, in units of far (as the stored depths)
uniform int pcf;                // odd block size k; 1: one texel, hard 0/1 shadows

out vec4 result;

// Given: the linear depth at texel (col, row) of cube face `face` (row 0 at the top), clamped to the face:
// PCF does not cross cube faces, it reads the face's border (as the NumPy route does).
float map_depth(int face, int col, int row) {
    int size = textureSize(cube_maps, 0).y;
    col = clamp(col, 0, size - 1);
    row = clamp(row, 0, size - 1);
    return texelFetch(cube_maps, ivec2(face * size + col, size - 1 - row), 0).r;
}

// The cube face the direction d (from the light) falls in: 2 a + (d_a < 0) with a the axis of the largest
// |d_i|, the first one on ties (cube_face_index); its |d_a| is returned in ma.
int cube_face(vec3 d, out float ma) {
    // BEGIN SOLUTION: Task 12 (cube shadow lookup): a = argmax |d_i| (first axis on ties); face = 2 a + (d_a < 0); ma = |d_a|
    vec3 ad = abs(d);
    int a = 0;
    if (ad.y > ad[a]) {
        a = 1;
    }
    if (ad.z > ad[a]) {
        a = 2;
    }
    ma = ad[a];
    return 2 * a + (d[a] < 0.0 ? 1 : 0);
    // END SOLUTION
}

// (s, t) in [0, 1]^2 of direction d on its face: OpenGL's cube-map table (spec 8.13), s = (sc / |ma| + 1) / 2,
// t = (tc / |ma| + 1) / 2. They are the face camera's (u, v) of Task 8 (u right, v up).
vec2 face_st(vec3 d, int face, float ma) {
    // BEGIN SOLUTION: Task 12 (cube shadow lookup): (sc, tc) = +x: (-z, -y), -x: (z, -y), +y: (x, z), -y: (x, -z), +z: (x, -y), -z: (-x, -y); st = ((sc, tc) / ma + 1) / 2
    vec2 sctc;
    if (face == 0) {
        sctc = vec2(-d.z, -d.y);
    } else if (face == 1) {
        sctc = vec2(d.z, -d.y);
    } else if (face == 2) {
        sctc = vec2(d.x, d.z);
    } else if (face == 3) {
        sctc = vec2(d.x, -d.z);
    } else if (face == 4) {
        sctc = vec2(d.x, -d.y);
    } else {
        sctc = vec2(-d.x, -d.y);
    }
    return (sctc / ma + 1.0) * 0.5;
    // END SOLUTION
}

float visibility(vec3 P) {
    vec3 d = P - lightPos;
    if (d == vec3(0.0)) {
        return 1.0;  // the light itself: no direction, no map
    }
    float ma;
    int face = cube_face(d, ma);
    // BEGIN SOLUTION: Task 12 (cube shadow lookup): lit beyond the far plane (ma > far); depth = |d| / far - bias; (col, row) = (floor(s size), size - 1 - floor(t size)); k = 1: [depth <= D]; else mean over the k x k block of [depth <= D(face, col + i, row - j)]
    if (ma > far) {
        return 1.0;
    }
    float size = float(textureSize(cube_maps, 0).y);
    vec2 st = face_st(d, face, ma);
    float depth = length(d) / far - bias;
    int col = int(floor(st.x * size));
    int row = int(size) - 1 - int(floor(st.y * size));
    int h = (pcf - 1) / 2;
    float lit = 0.0;
    for (int i = -h; i <= h; ++i) {
        for (int j = -h; j <= h; ++j) {
            lit += depth <= map_depth(face, col + i, row - j) ? 1.0 : 0.0;
        }
    }
    return lit / float(pcf * pcf);
    // END SOLUTION
}

void main() {
    vec3 P = texelFetch(position_in, ivec2(gl_FragCoord.xy), 0).xyz;
    result = vec4(visibility(P), 0.0, 0.0, 1.0);
}
