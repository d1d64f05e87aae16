#version 330 core
// Task 10 in GLSL: the shadow test, one surface point per fragment (see shadow_visibility in lookup.py:
// the same light_uvz, receiver_depth_gradient, shadow_bias, outside_frustum, pcf_visibility and
// poisson_pcf_visibility). The point's world position and geometric normal arrive as float textures read
// with texelFetch at the fragment's own pixel. Output: result = (visibility in [0, 1], 0, 0, 1).

uniform sampler2D position_in;  // world position P of the point
uniform sampler2D normal_in;    // its geometric (face) normal N, any length
uniform sampler2D shadow_map;   // D (size x size): window depth, row 0 = the top of the map (v = 1)
uniform sampler2D rotation;     // given: Poisson-disk rotation angle per texel (see rotation_angle)
uniform mat4 lightSpaceMatrix;  // M: clip from world
uniform mat4 lightInverse;      // M^-1 (given: inverted in double precision on the CPU)
uniform float bias;             // constant bias, window-depth units
uniform float slope_bias;       // factor of the slope-scaled part
uniform float max_slope;        // clamp of the NDC depth slope
uniform int pcf;                // odd block size k; 1: one texel, hard 0/1 shadows
uniform int poisson;            // 1: n_disk samples on a rotated Poisson disk instead of the k x k block
uniform int n_disk;
uniform vec2 disk[64];          // the disk's offsets in texels (radius k / 2 already applied)
uniform int frustum_fix;        // 1: points outside the light's frustum are lit (Task 6)

out vec4 result;

// Given: D at texel (col, row) of the map, row 0 at the top, both clamped to the map (GL_CLAMP_TO_EDGE).
float map_depth(int col, int row) {
    int size = textureSize(shadow_map, 0).x;
    col = clamp(col, 0, size - 1);
    row = clamp(row, 0, size - 1);
    return texelFetch(shadow_map, ivec2(col, size - 1 - row), 0).r;
}

// Given: the rotation of the disk at continuous texel coordinates (x, y) = (u size, v size), y up: the
// angle poisson_pcf_visibility's integer hash gives texel (floor(x), floor(y)).
float rotation_angle(float x, float y) {
    ivec2 r = textureSize(rotation, 0);
    ivec2 t = clamp(ivec2(int(floor(x)), int(floor(y))) + 1, ivec2(0), r - 1);
    return texelFetch(rotation, t, 0).r;
}

// (u, v, z) of P in the shadow map; behind = true where clip w <= 0 (level with or behind the light).
vec3 light_uvz(vec3 P, out bool behind) {
    // BEGIN SOLUTION: Task 10 (fragment shadow test): (x, y, z, w) = lightSpaceMatrix (P, 1); behind = w <= 0; uvz = (xyz / w + 1) / 2
    vec4 c = lightSpaceMatrix * vec4(P, 1.0);
    behind = c.w <= 0.0;
    return (c.xyz / c.w + 1.0) * 0.5;
    // END SOLUTION
}

// (dz/du, dz/dv) per texel of the plane through P with normal N (receiver_depth_gradient).
vec2 depth_gradient(vec3 P, vec3 N, float size) {
    // BEGIN SOLUTION: Task 10 (fragment shadow test): (a, b, c, d) = M^-T (N, -N.P); s = -(a, b) / c (c = 0: +-max_slope by the sign of -(a, b), 0 where a or b is 0); g = clamp(s, -max_slope, max_slope) / size
    vec4 abcd = vec4(N, -dot(N, P)) * lightInverse;  // row vector times M^-1 = M^-T (N, -N.P)
    vec2 s;
    if (abcd.z != 0.0) {
        s = -abcd.xy / abcd.z;
    } else {
        s = -sign(abcd.xy) * max_slope;
    }
    return clamp(s, -max_slope, max_slope) / size;
    // END SOLUTION
}

bool outside_frustum(vec3 uvz) {
    // BEGIN SOLUTION: Task 10 (fragment shadow test): u or v outside [0, 1], or z > 1 (z < 0 is not outside)
    return uvz.x < 0.0 || uvz.x > 1.0 || uvz.y < 0.0 || uvz.y > 1.0 || uvz.z > 1.0;
    // END SOLUTION
}

float visibility(vec3 P, vec3 N) {
    float size = float(textureSize(shadow_map, 0).x);
    bool behind;
    vec3 uvz = light_uvz(P, behind);
    if (behind) {
        return 1.0;  // no map can hold it
    }
    // BEGIN SOLUTION: Task 10 (fragment shadow test): lit outside the frustum (frustum_fix); b = bias + slope_bias (|g_u| + |g_v|) / 2; k = 1: [z - b <= D]; grid: mean over the k x k block of [z + g.(i, j) - b <= D(col + i, row - j)]; poisson: mean over the rotated disk offsets (dx, dy) of [z + g.(dx, dy) - b <= D(floor(x + dx), size - 1 - floor(y + dy))]
    if (frustum_fix != 0 && outside_frustum(uvz)) {
        return 1.0;
    }
    vec2 g = depth_gradient(P, N, size);
    float z = uvz.z - (bias + slope_bias * 0.5 * (abs(g.x) + abs(g.y)));
    float x = uvz.x * size;
    float y = uvz.y * size;
    int col = int(floor(x));
    int row = int(size) - 1 - int(floor(y));
    if (pcf == 1) {
        return z <= map_depth(col, row) ? 1.0 : 0.0;
    }
    float lit = 0.0;
    if (poisson != 0) {
        float t = rotation_angle(x, y);
        float ct = cos(t);
        float st = sin(t);
        for (int s = 0; s < n_disk; ++s) {
            float dx = ct * disk[s].x - st * disk[s].y;
            float dy = st * disk[s].x + ct * disk[s].y;
            int c = int(floor(x + dx));
            int r = int(size) - 1 - int(floor(y + dy));
            lit += z + g.x * dx + g.y * dy <= map_depth(c, r) ? 1.0 : 0.0;
        }
        return lit / float(n_disk);
    }
    int h = (pcf - 1) / 2;
    for (int i = -h; i <= h; ++i) {
        for (int j = -h; j <= h; ++j) {
            lit += z + g.x * float(i) + g.y * float(j) <= map_depth(col + i, row - j) ? 1.0 : 0.0;
        }
    }
    return lit / float(pcf * pcf);
    // END SOLUTION
}

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec3 P = texelFetch(position_in, p, 0).xyz;
    vec3 N = texelFetch(normal_in, p, 0).xyz;
    result = vec4(visibility(P, N), 0.0, 0.0, 1.0);
}
