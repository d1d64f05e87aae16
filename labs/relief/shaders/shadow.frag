#version 330 core
// Task 4 in GLSL: self-shadowing (see relief_shadow in shadow.py). From the hit point (uv, depth)
// step k = 1..layers towards the light: d_k = depth (1 - k / layers),
// uv_k = uv + (depth - d_k) light.xy / light.z; in shadow if some d_k > scale (1 - h(uv_k)).
// Output: result = (visibility, 0, 0, 1), visibility 1 (lit) or 0 (in shadow).

uniform sampler2D height;    // (s, s) heights in [0, 1], white = high
uniform sampler2D uv_in;     // per pixel: uv of the relief point (e.g. from relief.frag)
uniform sampler2D depth_in;  // per pixel: its depth below the polygon
uniform sampler2D light_in;  // per pixel: tangent-space unit vector towards the light (z > 0)
uniform float scale;
uniform int layers;

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

float visibility(vec2 uv, float depth, vec3 light) {
    #error Task 4 (shadow): d_k = depth (1 - k/layers), uv_k = uv + (depth - d_k) light.xy / light.z; 0 if any d_k > scale (1 - h(uv_k))
}

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec2 uv = texelFetch(uv_in, p, 0).xy;
    float depth = texelFetch(depth_in, p, 0).r;
    vec3 light = normalize(texelFetch(light_in, p, 0).xyz);
    result = vec4(visibility(uv, depth, light), 0.0, 0.0, 1.0);
}
