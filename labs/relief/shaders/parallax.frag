#version 330 core
// Task 2 in GLSL: parallax mapping, with or without offset limiting (see parallax_uv in parallax.py).
// One fragment per pixel; its uv and tangent-space view vector come from the textures uv_in and view_in.
// Output: result = (u', v', 0, 1).

uniform sampler2D height;   // (s, s) heights in [0, 1], white = high
uniform sampler2D uv_in;    // per pixel: uv where the view ray enters the polygon
uniform sampler2D view_in;  // per pixel: tangent-space unit vector towards the eye (z > 0)
uniform float scale;        // depth of the relief where h = 0 (UV units)
uniform float bias;         // hsb = scale * h + bias (bias = -scale: the relief lies below the polygon)
uniform int offset_limit;   // 1: offset limiting (shift by hsb * view.xy)

out vec4 result;

// Given: the height map read bilinearly with clamp-to-edge, exactly like height_at in inputs.py
// (texelFetch, not texture(): GPU filtering weights have only a few bits of precision).
// Image row r is GL row s - 1 - r (geomlib.gl uploads row 0 = v = 1 at the top).
float height_at(vec2 p) {
    ivec2 size = textureSize(height, 0);
    float s = float(size.x);
    float x = p.x * s - 0.5;
    float y = (1.0 - p.y) * s - 0.5;
    float x0 = floor(x);
    float y0 = floor(y);
    float fx = x - x0;
    float fy = y - y0;
    int xa = int(clamp(x0, 0.0, s - 1.0));
    int xb = int(clamp(x0 + 1.0, 0.0, s - 1.0));
    int ya = size.y - 1 - int(clamp(y0, 0.0, s - 1.0));
    int yb = size.y - 1 - int(clamp(y0 + 1.0, 0.0, s - 1.0));
    float t00 = texelFetch(height, ivec2(xa, ya), 0).r;
    float t01 = texelFetch(height, ivec2(xb, ya), 0).r;
    float t10 = texelFetch(height, ivec2(xa, yb), 0).r;
    float t11 = texelFetch(height, ivec2(xb, yb), 0).r;
    float top = t00 + (t01 - t00) * fx;
    float bot = t10 + (t11 - t10) * fx;
    return top + (bot - top) * fy;
}

vec2 parallax_uv(vec2 uv, vec3 view) {
    #error Task 2 (parallax): hsb = scale h(uv) + bias; uv' = uv + hsb view.xy / view.z (offset limiting: uv + hsb view.xy)
}

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec2 uv = texelFetch(uv_in, p, 0).xy;
    vec3 view = normalize(texelFetch(view_in, p, 0).xyz);
    result = vec4(parallax_uv(uv, view), 0.0, 1.0);
}
