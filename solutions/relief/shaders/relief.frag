#version 330 core
// Task 3 in GLSL: steep parallax / parallax occlusion mapping (see relief_uv in relief.py).
// March d_i = i / n, i = 0..n, to the first f(d_i) = d_i - (1 - h(uv(d_i))) >= 0 with
// uv(d) = uv + d * duv, duv = -scale * view.xy / view.z; then refine between a = d_(i-1) and b = d_i.
// Output: result = (u', v', depth = scale * d, i).

uniform sampler2D height;   // (s, s) heights in [0, 1], white = high
uniform sampler2D uv_in;    // per pixel: uv where the view ray enters the polygon
uniform sampler2D view_in;  // per pixel: tangent-space unit vector towards the eye (z > 0)
uniform float scale;
uniform int min_layers;
uniform int max_layers;
uniform int refine;         // 0 none, 1 linear, 2 secant, 3 binary
uniform int refine_steps;

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

// Given: how far below the relief the ray point at normalised depth d is.
float below(vec2 uv, vec2 duv, float d) {
    return d - (1.0 - height_at(uv + d * duv));
}

// Given: the layer count, n = floor(min + (max - min)(1 - view.z) + 1/2).
int layer_count(float view_z) {
    return int(floor(float(min_layers) + float(max_layers - min_layers) * (1.0 - view_z) + 0.5));
}

vec4 relief(vec2 uv, vec3 view) {
    vec2 duv = -scale * view.xy / view.z;
    int n = layer_count(view.z);
    float d = 0.0;
    int hit = 0;
    // BEGIN SOLUTION: Task 3 (march and refine): first i with below(d_i) >= 0, then none / linear / secant / binary as in relief_uv
    float f_above = 0.0;
    float f_hit = 0.0;
    for (int i = 0; i <= n; ++i) {
        float fi = below(uv, duv, float(i) / float(n));
        if (fi >= 0.0) {
            hit = i;
            f_hit = fi;
            break;
        }
        f_above = fi;
    }
    float b = float(hit) / float(n);
    float a = float(max(hit - 1, 0)) / float(n);
    d = b;
    if (hit > 0) {
        if (refine == 1) {
            d = a + (b - a) * f_above / (f_above - f_hit);
        } else if (refine == 2) {
            float x0 = a, f0 = f_above, x1 = b, f1 = f_hit;
            for (int k = 0; k < refine_steps; ++k) {
                float den = f1 - f0;
                float x2 = den == 0.0 ? x1 : clamp(x1 - f1 * (x1 - x0) / den, a, b);
                float f2 = below(uv, duv, x2);
                x0 = x1; f0 = f1; x1 = x2; f1 = f2;
            }
            d = x1;
        } else if (refine == 3) {
            float lo = a, hi = b;
            for (int k = 0; k < refine_steps; ++k) {
                float mid = 0.5 * (lo + hi);
                if (below(uv, duv, mid) >= 0.0) hi = mid; else lo = mid;
            }
            d = 0.5 * (lo + hi);
        }
    }
    // END SOLUTION
    return vec4(uv + d * duv, scale * d, float(hit));
}

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec2 uv = texelFetch(uv_in, p, 0).xy;
    vec3 view = normalize(texelFetch(view_in, p, 0).xyz);
    result = relief(uv, view);
}
