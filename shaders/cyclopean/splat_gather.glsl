// The splat-gather method's per-pixel sampling and merging (src/cyclopean/splat.rs), shared by
// the gather draw (splat_gather.frag) and the edge pass (splat_edges.comp). The f64 twin is
// src/cyclopean/splat_reference.rs: keep them in step.

// Parameters (`SplatGatherParams` in src/cyclopean/splat.rs), one block for GL and Vulkan,
// shared by the gather draw and the edge pass.
layout(std140, binding = 0) PARAM_BLOCK SplatGatherParams {
    mat4 u_view_proj_l;
    mat4 u_view_l;
    mat4 u_inv_view_l;
    mat4 u_ray_basis_l;
    mat4 u_view_proj_r;
    mat4 u_view_r;
    mat4 u_inv_view_r;
    mat4 u_ray_basis_r;
    mat4 u_view_m;
    mat4 u_inv_view_m;
    mat4 u_ray_basis_m;
    vec2 u_size_m;
    float u_parallax_px;  // focal (px) x baseline: full-baseline disparity = this / distance
    float u_tolerance_px;
    float u_w_left;
};
layout(binding = 1) uniform sampler2D u_color_l;  // RGBA8, memory order
layout(binding = 2) uniform sampler2D u_dist_l;   // R32F eye view distance, memory order (0 = invalid)
layout(binding = 3) uniform usampler2D u_splat_l; // R32UI nearest splatted middle distance (bits), 0xFFFFFFFF = none
layout(binding = 4) uniform sampler2D u_color_r;
layout(binding = 5) uniform sampler2D u_dist_r;
layout(binding = 6) uniform usampler2D u_splat_r;

// No splat (a sentinel beyond any finite distance the splat can store).
const float NONE = 3.4e38;
// Sub-pixel sample offset along x at depth edges (pixels).
const float SUBSAMPLE = 1.0 / 3.0;

bool absent(float z) {
    return z >= NONE;
}

bool same_surface(float z1, float z2) {
    return abs(u_parallax_px / z1 - u_parallax_px / z2) <= u_tolerance_px;
}

struct Sample {
    bool valid;
    vec3 color;
    float z_middle;
    float confidence;
};

// Eye texel coordinates (texel i's centre at i) and eye distance of the middle ray point at z.
bool to_eye(mat4 view_proj, mat4 view, ivec2 size, vec3 ray_m, float z, out vec2 e, out float z_eye) {
    vec3 world = transform_point(u_inv_view_m, ray_m * z);
    vec4 clip = view_proj * vec4(world, 1.0);
    if (!(clip.w > 0.0)) {
        return false;
    }
    e = window_of_clip(clip, vec2(size)) - 0.5;
    z_eye = -transform_point(view, world).z;
    return true;
}

// The nearest texel to e, which must be on z_eye's surface: its distance, or -1.
float nearest_on_surface(sampler2D dist, vec2 e, float z_eye) {
    ivec2 size = textureSize(dist, 0);
    vec2 n = floor(e + 0.5);
    if (any(lessThan(n, vec2(0.0))) || any(greaterThanEqual(n, vec2(size)))) {
        return -1.0;
    }
    float zn = texelFetch(dist, ivec2(n), 0).r;
    return (zn > 0.0 && z_eye > 0.0 && same_surface(zn, z_eye)) ? zn : -1.0;
}

// The bilinear taps of e on the surface of distance zn: interpolated distance (inverse depth),
// colour (WITH_COLOR), kept weight. Two variants so that llvmpipe, which runs both sides of a
// branch, does not pay for colour fetches in the first step.
#define TAPS(WITH_COLOR)                                                                   \
    ivec2 size = textureSize(dist, 0);                                                    \
    vec2 f0 = floor(e);                                                                   \
    vec2 fr = e - f0;                                                                     \
    ivec2 i0 = ivec2(f0);                                                                 \
    float inv = 0.0;                                                                      \
    total = 0.0;                                                                          \
    for (int k = 0; k < 4; ++k) {                                                         \
        ivec2 o = tap_offset(k);                                                          \
        ivec2 tx = clamp(i0 + o, ivec2(0), size - 1);                                     \
        float w = tap_weight(o, fr);                                                      \
        float z = texelFetch(dist, tx, 0).r;                                              \
        float keep = (z > 0.0 && same_surface(z, zn)) ? w : 0.0;                          \
        inv += keep / max(z, 1e-30);                                                      \
        total += keep;                                                                    \
        WITH_COLOR                                                                        \
    }                                                                                     \
    z_surface = total / inv;

void surface_depth(sampler2D dist, vec2 e, float zn, out float z_surface, out float total) {
    TAPS(;)  // no colour: an empty statement (glslang refuses an empty macro argument)
}

void surface_color(sampler2D dist, sampler2D color, vec2 e, float zn, out float z_surface, out vec3 c,
                   out float total) {
    c = vec3(0.0);
    TAPS(c += keep * texelFetch(color, tx, 0).rgb * 255.0;)
    c /= total;
}

Sample eye_sample(sampler2D color, sampler2D dist, mat4 view_proj, mat4 view, mat4 inv_view, mat4 ray_basis,
                  vec3 ray_m, float z0) {
    Sample none = Sample(false, vec3(0.0), 0.0, 0.0);
    ivec2 size = textureSize(dist, 0);
    vec2 e0;
    float z_eye0;
    if (!to_eye(view_proj, view, size, ray_m, z0, e0, z_eye0)) {
        return none;
    }
    float zn = nearest_on_surface(dist, e0, z_eye0);
    if (zn < 0.0) {
        return none;
    }
    float z_surface, total;
    surface_depth(dist, e0, zn, z_surface, total);
    vec2 ndc = ndc_of_pixel(e0, vec2(size));
    vec3 on_surface = transform_point(inv_view, view_ray(ray_basis, ndc) * z_surface);
    float z1 = -transform_point(u_view_m, on_surface).z;
    if (!(z1 > 0.0) || isinf(z1)) {
        return none;
    }
    vec2 e1;
    float z_eye1;
    if (!to_eye(view_proj, view, size, ray_m, z1, e1, z_eye1)) {
        return none;
    }
    zn = nearest_on_surface(dist, e1, z_eye1);
    if (zn < 0.0) {
        return none;
    }
    vec3 c;
    surface_color(dist, color, e1, zn, z_surface, c, total);
    return Sample(true, c, z1, total);
}

float splat_at(usampler2D splat, ivec2 p) {
    uint bits = texelFetch(splat, p, 0).r;
    return bits == 0xFFFFFFFFu ? NONE : uintBitsToFloat(bits);
}

// One eye's splats around pixel p, fetched once for all of the pixel's samples: the
// candidates (the nearest of the pixel's and its 4 neighbours' splats, then the pixel's own (in
// a hole: the farthest neighbour's) when it is another surface; NONE where absent), and whether
// a depth edge may cross the pixel along x (two of it and its left and right neighbours hold
// different surfaces; an empty one is a crack or the other eye's edge, not an edge here).
struct Neighbourhood {
    vec2 cand;
    bool edge;
};

Neighbourhood neighbourhood(usampler2D splat, ivec2 p) {
    ivec2 size = ivec2(u_size_m);
    float own = splat_at(splat, p);
    float near = own;
    float far = absent(own) ? -1.0 : own;
    // Along x (a neighbour outside the image counts as the pixel itself).
    float lo = own;
    float hi = absent(own) ? 0.0 : own;
    ivec2 offsets[4] = ivec2[4](ivec2(-1, 0), ivec2(1, 0), ivec2(0, -1), ivec2(0, 1));
    for (int k = 0; k < 4; ++k) {
        ivec2 q = p + offsets[k];
        if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) {
            continue;
        }
        float z = splat_at(splat, q);
        near = min(near, z);
        if (absent(own) && !absent(z)) {
            far = max(far, z);
        }
        if (k < 2 && !absent(z)) {
            lo = min(lo, z);
            hi = max(hi, z);
        }
    }
    float second = (far > 0.0 && !same_surface(far, near)) ? far : NONE;
    return Neighbourhood(vec2(near, second), hi > 0.0 && !same_surface(lo, hi));
}

Sample eye(sampler2D color, sampler2D dist, mat4 view_proj, mat4 view, mat4 inv_view, mat4 ray_basis, vec3 ray_m,
           vec2 cand) {
    Sample s = Sample(false, vec3(0.0), 0.0, 0.0);
    // A loop, not two branches: llvmpipe leaves it as soon as every lane has its answer.
    for (int k = 0; k < 2; ++k) {
        float z0 = k == 0 ? cand.x : cand.y;
        if (!absent(z0)) {
            s = eye_sample(color, dist, view_proj, view, inv_view, ray_basis, ray_m, z0);
            if (s.valid) {
                break;
            }
        }
    }
    return s;
}

struct Merged {
    bool valid;
    vec3 color;
    float z;
    int bits;
};

// Both eyes' answers for the middle ray through window position `frag`, from the pixel's splat
// candidates, merged: on one surface weighted by nearness to each eye and confidence; else the
// nearer; one eye alone: that eye.
Merged shade(vec2 frag, vec2 cand_l, vec2 cand_r) {
    vec2 ndc = (2.0 * frag - u_size_m) / u_size_m;  // exactly mirrored under the other row order
    vec3 ray = view_ray(u_ray_basis_m, ndc);
    Sample l = eye(u_color_l, u_dist_l, u_view_proj_l, u_view_l, u_inv_view_l, u_ray_basis_l, ray, cand_l);
    Sample r = eye(u_color_r, u_dist_r, u_view_proj_r, u_view_r, u_inv_view_r, u_ray_basis_r, ray, cand_r);
    Merged m = Merged(false, vec3(0.0), 0.0, 0);
    if (l.valid && r.valid && same_surface(l.z_middle, r.z_middle)) {
        // > 0: each confidence is >= 1/4 and the two position weights sum to 1.
        float wl = u_w_left * l.confidence;
        float wr = (1.0 - u_w_left) * r.confidence;
        m = Merged(true, (wl * l.color + wr * r.color) / (wl + wr), (wl * l.z_middle + wr * r.z_middle) / (wl + wr), 3);
    } else if (l.valid && (!r.valid || l.z_middle <= r.z_middle)) {
        m = Merged(true, l.color, l.z_middle, 1);
    } else if (r.valid) {
        m = Merged(true, r.color, r.z_middle, 2);
    }
    return m;
}
