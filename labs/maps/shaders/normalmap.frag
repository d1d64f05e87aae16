#version 330 core
// Task 8 in GLSL: per-fragment normal mapping and Blinn-Phong (see shade in shading.py: the same lighting).
// One fragment per pixel of the G-buffer; its interpolated attributes arrive as float textures read with
// texelFetch at the fragment's own pixel. Output: result = (r, g, b, 1) before clipping to [0, 1].

uniform sampler2D position_in;  // world position P
uniform sampler2D normal_in;    // interpolated vertex normal (not unit length)
uniform sampler2D uv_in;        // interpolated uv
uniform sampler2D tangent_in;   // interpolated [T, w] (from tbn.vert in a full pipeline)
uniform sampler2D normal_map;   // tangent-space normals encoded as rgb = (m + 1) / 2 (uint8 maps: codes / 255)
uniform sampler2D albedo_map;   // albedo texture (used when use_albedo_map = 1)
uniform int use_normal_map;     // 0: shade with the interpolated normal
uniform int use_albedo_map;     // 0: the constant albedo
uniform int repeat_wrap;        // texture lookups: 1 = "repeat", 0 = "clamp"
uniform vec3 albedo;
uniform vec3 eye;               // camera position (world)
uniform float ambient;
uniform float specular;
uniform float shininess;
uniform int n_lights;           // at most 4
uniform int light_kind[4];      // 0: directional (light_vec = the way the light travels), 1: point (light_vec = position)
uniform vec3 light_vec[4];
uniform vec3 light_rgb[4];      // colour times intensity

out vec4 result;

// Given: bilinear lookup exactly like geomlib.textures.sample_bilinear (texelFetch: GPU filtering
// weights have only a few bits of precision). Row r of the image is GL row h - 1 - r.
vec3 texel(sampler2D tex, ivec2 size, int x, int y) {
    if (repeat_wrap != 0) {
        x -= size.x * int(floor(float(x) / float(size.x)));  // GLSL's % of a negative int is undefined
        y -= size.y * int(floor(float(y) / float(size.y)));
    } else {
        x = clamp(x, 0, size.x - 1);
        y = clamp(y, 0, size.y - 1);
    }
    return texelFetch(tex, ivec2(x, size.y - 1 - y), 0).rgb;
}

vec3 bilinear(sampler2D tex, vec2 p) {
    ivec2 size = textureSize(tex, 0);
    float x = p.x * float(size.x) - 0.5;
    float y = (1.0 - p.y) * float(size.y) - 0.5;
    float x0 = floor(x);
    float y0 = floor(y);
    float fx = x - x0;
    float fy = y - y0;
    int xa = int(x0);
    int ya = int(y0);
    vec3 t00 = texel(tex, size, xa, ya);
    vec3 t01 = texel(tex, size, xa + 1, ya);
    vec3 t10 = texel(tex, size, xa, ya + 1);
    vec3 t11 = texel(tex, size, xa + 1, ya + 1);
    vec3 top = t00 + (t01 - t00) * fx;
    vec3 bot = t10 + (t11 - t10) * fx;
    return top + (bot - top) * fy;
}

vec3 shading_normal(vec3 n_interp, vec4 t, vec2 uv) {
    if (use_normal_map == 0) {
        return normalize(n_interp);
    }
    #error Task 8 (fragment normal mapping): m = 2 rgb - 1; N' = normalize(n), T' = normalize(T - (N'.T) N'), B' = sign(w) N' x T'; n = normalize(m.x T' + m.y B' + m.z N')
}

vec3 blinn_phong(vec3 P, vec3 n, vec3 colour) {
    #error Task 8 (fragment Blinn-Phong): ambient albedo + sum L (albedo max(n.l, 0) + specular max(n.h, 0)^shininess [n.l > 0])
}

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec3 P = texelFetch(position_in, p, 0).xyz;
    vec3 n_interp = texelFetch(normal_in, p, 0).xyz;
    vec2 uv = texelFetch(uv_in, p, 0).xy;
    vec4 t = texelFetch(tangent_in, p, 0);
    vec3 colour = use_albedo_map != 0 ? bilinear(albedo_map, uv) : albedo;
    result = vec4(blinn_phong(P, shading_normal(n_interp, t, uv), colour), 1.0);
}
