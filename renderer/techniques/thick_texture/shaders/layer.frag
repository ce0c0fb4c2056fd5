#version 450 core
// One sheet layer (depth peeled behind the previous one with PEEL): the thick texture's
// premultiplied colour rho_op c1 + rho_occ c2 and alpha rho_op + rho_occ (Eq. 3.4.3; the
// transparent part is composited later). Variants:
//   THIN         rho_occ = 0: a plain premultiplied alpha texture (h = 0, or no hole)
//   THESIS_PATH  Algorithm 3.1 on 8 texels of 2 levels by texelFetch (Sec. 3.5)
//   (default)    Algorithm 3.1 once on hardware-filtered normalised averages
//   BINS 4|8     the wide-hole fix on run-length histograms
// Filtering: the samplers carry the knob's filter; THESIS_PATH imitates it with
// FILTER_TEXEL_LINEAR / FILTER_MIP_LINEAR. Same equations as model.cpp.
in vec3 v_position_eye;
in vec3 v_normal_eye;
in vec2 v_st;
#ifndef THIN
in vec4 v_tangent_eye;
uniform sampler2D walls;      // top, left, bottom, right (averages)
uniform sampler2D triangles;  // TR, TL, BL, BR (averages, 0..2)
uniform float u_thickness;    // h, level-0 texels
uniform vec3 u_wall_colour;   // c2
#endif
uniform sampler2D albedo;     // rgb = c1 * opaque (premultiplied average), a = rho_op
#ifdef BINS
uniform sampler2D bins_r[BINS / 4];
uniform sampler2D bins_l[BINS / 4];
uniform sampler2D bins_u[BINS / 4];
uniform sampler2D bins_d[BINS / 4];
#endif
#ifdef PEEL
uniform sampler2D previous_depth;
uniform float u_epsilon;
#endif
layout(location = 0) out vec4 o_colour;

#ifndef THIN
struct Record {
    vec4 albedo, walls, triangles;
};

// Algorithm 3.1 corrected (README): |r|, the facing walls, a, b clamped to 1.
float occluded_of(Record t, vec2 r) {
    float a = min(abs(r.x), 1.0), b = min(abs(r.y), 1.0);
    float h = r.x > 0.0 ? t.walls.w : (r.x < 0.0 ? t.walls.y : 0.0);
    float v = r.y > 0.0 ? t.walls.x : (r.y < 0.0 ? t.walls.z : 0.0);
    float d = 0.0;
    if (r.x > 0.0 && r.y > 0.0) d = t.triangles.x;
    if (r.x < 0.0 && r.y > 0.0) d = t.triangles.y;
    if (r.x < 0.0 && r.y < 0.0) d = t.triangles.z;
    if (r.x > 0.0 && r.y < 0.0) d = t.triangles.w;
    return h * (a - a * b * 0.5) + v * (b - a * b * 0.5) + d * a * b * 0.5;
}

vec4 colour_of(Record t, vec2 r) {
    float opaque = clamp(t.albedo.a, 0.0, 1.0);
    float occluded = clamp(occluded_of(t, r), 0.0, 1.0 - opaque);
    return vec4(t.albedo.rgb + occluded * u_wall_colour, opaque + occluded);
}

#ifdef THESIS_PATH
ivec2 wrapped(ivec2 texel, ivec2 size) { return ((texel % size) + size) % size; }
// Level sizes from level 0: llvmpipe's textureSize(sampler, lod) with a lod that differs
// across the pixels shaded together returns one pixel's size for all of them (seen as
// 2-pixel columns of wrong texels where the level changes).
ivec2 level_size(int level) { return max(textureSize(albedo, 0) >> level, ivec2(1)); }
Record fetch(ivec2 texel, int level) {
    ivec2 size = level_size(level);
    ivec2 q = wrapped(texel, size);
    return Record(texelFetch(albedo, q, level), texelFetch(walls, q, level),
                  texelFetch(triangles, q, level));
}
// One level: the nearest texel or the bilinear blend of four evaluated colours.
vec4 level_colour(vec2 st, int level, vec2 r) {
    vec2 size = vec2(level_size(level));
#ifdef FILTER_TEXEL_LINEAR
    vec2 p = st * size - 0.5;
    ivec2 base = ivec2(floor(p));
    vec2 f = p - floor(p);
    vec4 c00 = colour_of(fetch(base, level), r);
    vec4 c10 = colour_of(fetch(base + ivec2(1, 0), level), r);
    vec4 c01 = colour_of(fetch(base + ivec2(0, 1), level), r);
    vec4 c11 = colour_of(fetch(base + ivec2(1, 1), level), r);
    return mix(mix(c00, c10, f.x), mix(c01, c11, f.x), f.y);
#else
    return colour_of(fetch(ivec2(floor(st * size)), level), r);
#endif
}
#endif
#endif

void main() {
#ifdef PEEL
    float previous = texelFetch(previous_depth, ivec2(gl_FragCoord.xy), 0).r;
    if (gl_FragCoord.z <= previous + u_epsilon) discard;
#endif
#ifdef THIN
    o_colour = texture(albedo, v_st);
#else
    // The propagation direction in the re-orthonormalised tangent frame (Gram-Schmidt on
    // the interpolated N and T, as the reference does).
    vec3 n = normalize(v_normal_eye);
    vec3 t = v_tangent_eye.xyz - n * dot(n, v_tangent_eye.xyz);
    if (dot(t, t) < 1e-20) t = abs(n.x) < 0.9 ? cross(n, vec3(1, 0, 0)) : cross(n, vec3(0, 1, 0));
    t = normalize(t);
    vec3 b = (v_tangent_eye.w < 0.0 ? -1.0 : 1.0) * cross(n, t);
    vec3 d = normalize(v_position_eye);
    // r = h (d.T, d.B) / |d.N| (Eq. 3.2.5), each magnitude capped at 64 texels so that
    // grazing rays stay finite.
    float dn = abs(dot(d, n));
    vec2 dt = vec2(dot(d, t), dot(d, b));
    vec2 m = u_thickness * abs(dt);
    vec2 magnitude = vec2(m.x >= 64.0 * dn ? (m.x > 0.0 ? 64.0 : 0.0) : m.x / dn,
                          m.y >= 64.0 * dn ? (m.y > 0.0 ? 64.0 : 0.0) : m.y / dn);
    vec2 r = sign(dt) * magnitude;
#ifdef THESIS_PATH
    // The LOD the hardware would use, split into two levels (Sec. 3.5).
    float max_level = float(textureQueryLevels(albedo) - 1);
    float lambda = textureQueryLod(albedo, v_st).y;
    vec4 colour;
    if (lambda <= 0.0) {
        colour = level_colour(v_st, 0, r);  // magnified: level 0 (the thesis gives no rule)
    } else {
#ifdef FILTER_MIP_LINEAR
        float l = min(lambda, max_level);
        int l0 = int(floor(l));
        int l1 = min(l0 + 1, int(max_level));
        colour = mix(level_colour(v_st, l0, r), level_colour(v_st, l1, r), l - float(l0));
#else
        // GL's nearest level: ceil(lambda + 1/2) - 1, clamped.
        int level = lambda <= 0.5 ? 0 : int(min(ceil(lambda + 0.5) - 1.0, max_level));
        colour = level_colour(v_st, level, r);
#endif
    }
    o_colour = colour;
#else
    Record filtered = Record(texture(albedo, v_st), texture(walls, v_st),
                             texture(triangles, v_st));
    float opaque = clamp(filtered.albedo.a, 0.0, 1.0);
    float occluded = occluded_of(filtered, r);
#ifdef BINS
    // Wide-hole fix: per-axis escape terms from the histograms, combined for rectangular
    // holes, minus the bin-0 part Algorithm 3.1 already counts.
    float hole = 1.0 - opaque;
    if (hole > 1e-6) {
        float ax = 0.0, ay = 0.0, ax0 = 0.0, ay0 = 0.0;
        for (int g = 0; g < BINS / 4; ++g) {
            vec4 nx = r.x > 0.0 ? texture(bins_r[g], v_st) : texture(bins_l[g], v_st);
            vec4 ny = r.y > 0.0 ? texture(bins_u[g], v_st) : texture(bins_d[g], v_st);
            vec4 k = vec4(0.0, 1.0, 2.0, 3.0) + 4.0 * float(g);
            if (r.x != 0.0) ax += dot(nx, clamp(abs(r.x) - k, 0.0, 1.0));
            if (r.y != 0.0) ay += dot(ny, clamp(abs(r.y) - k, 0.0, 1.0));
            if (g == 0) {
                ax0 = r.x != 0.0 ? nx.x * min(abs(r.x), 1.0) : 0.0;
                ay0 = r.y != 0.0 ? ny.x * min(abs(r.y), 1.0) : 0.0;
            }
        }
        occluded += (ax + ay - ax * ay / hole) - (ax0 + ay0 - ax0 * ay0 / hole);
    }
#endif
    occluded = clamp(occluded, 0.0, 1.0 - opaque);
    o_colour = vec4(filtered.albedo.rgb + occluded * u_wall_colour, opaque + occluded);
#endif
#endif
}
