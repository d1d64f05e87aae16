#version 330 core
// Task 9 in GLSL: displacement mapping in the vertex stage (see displace in displacement.py):
// P' = P + lam (bias + scale h(uv)) n, with h read bilinearly from the displacement map at the vertex's uv.
// One vertex per point; the given main() writes P' and the offset d = bias + scale h to two float targets.

in vec3 position;   // P (object space)
in vec3 normal;     // displacement direction (unit)
in vec2 uv;         // texture coordinates of the vertex
uniform sampler2D height;  // (s, s) displacement map, values in [0, 1] (black = no offset)
uniform float lam;         // mesh units
uniform float bias;        // d = bias + scale h maps [0, 1] onto [bias, bias + scale]
uniform float scale;
uniform int repeat_wrap;   // 1: wrap = "repeat" (tile the map), 0: "clamp" (clamp to edge)
uniform ivec2 grid;        // given: the read-back image's size (vertex i -> pixel (i % width, i / width))

flat out vec3 moved;
flat out float offset;

// Given: one texel, clamped to the edge or tiled (row r of the image is GL row s - 1 - r).
float texel(ivec2 size, int x, int y) {
    if (repeat_wrap != 0) {
        x -= size.x * int(floor(float(x) / float(size.x)));  // GLSL's % of a negative int is undefined
        y -= size.y * int(floor(float(y) / float(size.y)));
    } else {
        x = clamp(x, 0, size.x - 1);
        y = clamp(y, 0, size.y - 1);
    }
    return texelFetch(height, ivec2(x, size.y - 1 - y), 0).r;
}

// Given: the displacement map read bilinearly, exactly like geomlib.textures.sample_bilinear
// (texelFetch in the vertex stage: vertex shaders have no derivatives, so no mipmaps either).
float height_at(vec2 p) {
    ivec2 size = textureSize(height, 0);
    float x = p.x * float(size.x) - 0.5;
    float y = (1.0 - p.y) * float(size.y) - 0.5;
    float x0 = floor(x);
    float y0 = floor(y);
    float fx = x - x0;
    float fy = y - y0;
    int xa = int(x0);
    int ya = int(y0);
    float top = mix(texel(size, xa, ya), texel(size, xa + 1, ya), fx);
    float bot = mix(texel(size, xa, ya + 1), texel(size, xa + 1, ya + 1), fx);
    return mix(top, bot, fy);
}

float displacement(vec2 p) {
    #error Task 9 (vertex displacement): d = bias + scale h(uv)
}

vec3 displace(vec3 P, vec3 n, float d) {
    #error Task 9 (vertex displacement): P' = P + lam d n
}

// Given: vertex i becomes one point at pixel (i % width, i / width) of the read-back image.
vec4 point_position(int i) {
    vec2 pixel = vec2(float(i % grid.x), float(i / grid.x)) + 0.5;
    return vec4(pixel * 2.0 / vec2(grid) - 1.0, 0.0, 1.0);
}

void main() {
    offset = displacement(uv);
    moved = displace(position, normal, offset);
    gl_Position = point_position(gl_VertexID);
    gl_PointSize = 1.0;
}
