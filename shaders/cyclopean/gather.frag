// Cyclopean middle view, one full-screen pass (seed 000 section 4-5, with the fixes noted in
// src/cyclopean/mod.rs). The f64 twin is src/cyclopean/reference.rs: keep them in step.
// Defines: DEPTH_IS_DEVICE, REFINE (k-step + projection check + edge-aware colour), BLEND_SOFT,
// plus the conventions preamble (NDC_ZERO_TO_ONE, REVERSED_Z, ROWS_TOP_DOWN).

// Parameters and images: shaders/cyclopean/gather_params.glsl (one block, both backends).

layout(location = 0) out vec4 o_color;
layout(location = 1) out float o_depth;
layout(location = 2) out float o_sources;

const float REFINE_TOLERANCE_PX = 1.0;

bool depth_valid(float d) {
#if DEPTH_IS_DEVICE
    return !isnan(d) && !isinf(d) && !device_depth_is_background(d);
#else
    return !isnan(d) && !isinf(d) && d > 0.0;
#endif
}

// Eye view-space point at ndc with stored depth d (assumed valid): device depth through the
// inverse projection, a view distance along the pixel's ray (the ray basis).
vec3 eye_view_point(mat4 inv_proj, mat4 ray_basis, vec2 ndc, float d) {
#if DEPTH_IS_DEVICE
    return transform_point(inv_proj, vec3(ndc, ndc_z_of_window_depth(d)));
#else
    return view_ray(ray_basis, ndc) * d;
#endif
}

// View distance stored at texel t, or -1 for background.
float texel_distance(sampler2D depth, mat4 inv_proj, mat4 ray_basis, ivec2 t) {
    float d = texelFetch(depth, t, 0).r;
    if (!depth_valid(d)) {
        return -1.0;
    }
    vec2 ndc = ndc_of_pixel(vec2(t), vec2(textureSize(depth, 0)));
    return -eye_view_point(inv_proj, ray_basis, ndc, d).z;
}

// Bilinear colour at uv (clamp to edge); with REFINE, texels at another depth than z_eye get
// no weight (the texel holding uv always qualifies).
vec3 sample_color(sampler2D color, sampler2D depth, mat4 inv_proj, mat4 ray_basis, vec2 uv, float z_eye,
                  bool edge_aware) {
    ivec2 size = textureSize(color, 0);
    vec2 t = uv * vec2(size) - 0.5;
    vec2 f0 = floor(t);
    vec2 fr = t - f0;
    ivec2 i0 = ivec2(f0);
    vec3 sum = vec3(0.0);
    float total = 0.0;
    for (int k = 0; k < 4; ++k) {
        ivec2 o = tap_offset(k);
        ivec2 tx = clamp(i0 + o, ivec2(0), size - 1);
        float w = tap_weight(o, fr);
        bool keep = true;
        if (edge_aware) {
            float zt = texel_distance(depth, inv_proj, ray_basis, tx);
            keep = zt >= 0.0 && abs(zt - z_eye) <= u_z_threshold;
        }
        if (keep) {
            sum += w * texelFetch(color, tx, 0).rgb * 255.0;
            total += w;
        }
    }
    return total > 0.0 ? sum / total : sum;
}

struct EyeSample {
    bool valid;
    vec3 color;
    float z_middle;
};

EyeSample walk(sampler2D color, sampler2D depth, mat4 view_proj, mat4 inv_view, mat4 inv_proj, mat4 ray_basis,
               mat4 view, vec3 ray_m, vec2 pixel) {
    EyeSample invalid = EyeSample(false, vec3(0.0), 0.0);
    ivec2 size = textureSize(depth, 0);
    float z = u_fixation;
    vec2 uv = vec2(0.0);
    ivec2 texel = ivec2(0);
    vec3 world = vec3(0.0);
    for (int s = 0; s < u_steps; ++s) {
        vec3 guess = transform_point(u_inv_view_m, ray_m * z);
        vec4 clip = view_proj * vec4(guess, 1.0);
        if (!(clip.w > 0.0)) {
            return invalid;
        }
        vec2 ndc = clip.xy / clip.w;
        uv = ndc * 0.5 + 0.5;
        if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) {
            return invalid;
        }
        texel = clamp(ivec2(floor(uv * vec2(size))), ivec2(0), size - 1);
        float d = texelFetch(depth, texel, 0).r;
        if (!depth_valid(d)) {
            return invalid;
        }
        world = transform_point(inv_view, eye_view_point(inv_proj, ray_basis, ndc, d));
        z = -transform_point(u_view_m, world).z;
        if (!(z > 0.0) || isinf(z)) {
            return invalid;
        }
    }
    bool edge_aware = false;
#if REFINE
    float z_texel = texel_distance(depth, inv_proj, ray_basis, texel);
    if (z_texel < 0.0) {
        return invalid;
    }
    vec2 centre = ndc_of_pixel(vec2(texel), vec2(size));
    vec3 sample_ws = transform_point(inv_view, view_ray(ray_basis, centre) * z_texel);
    vec4 clip_m = u_view_proj_m * vec4(sample_ws, 1.0);
    vec2 px = window_of_clip(clip_m, u_size_m);
    if (any(greaterThan(abs(px - pixel), vec2(REFINE_TOLERANCE_PX)))) {
        return invalid;
    }
    edge_aware = true;
#endif
    float z_eye = -transform_point(view, world).z;
    return EyeSample(true, sample_color(color, depth, inv_proj, ray_basis, uv, z_eye, edge_aware), z);
}

void main() {
    vec2 pixel = gl_FragCoord.xy;
    vec2 uv = pixel / u_size_m;
    // Exactly mirrored under the other row order (2 pixel is an integer).
    vec3 ray = view_ray(u_ray_basis_m, (2.0 * pixel - u_size_m) / u_size_m);
    EyeSample l = walk(u_color_l, u_depth_l, u_view_proj_l, u_inv_view_l, u_inv_proj_l, u_ray_basis_l, u_view_l, ray, pixel);
    EyeSample r = walk(u_color_r, u_depth_r, u_view_proj_r, u_inv_view_r, u_inv_proj_r, u_ray_basis_r, u_view_r, ray, pixel);

    vec3 c;
    float z = 0.0;
    int bits = 0;
    if (!l.valid && !r.valid) {
        // The seed's fallback: both eyes at the same uv, averaged.
        c = 0.5 * (sample_color(u_color_l, u_depth_l, u_inv_proj_l, u_ray_basis_l, uv, 0.0, false)
                 + sample_color(u_color_r, u_depth_r, u_inv_proj_r, u_ray_basis_r, uv, 0.0, false));
    } else if (l.valid && !r.valid) {
        c = l.color; z = l.z_middle; bits = 1;
    } else if (!l.valid && r.valid) {
        c = r.color; z = r.z_middle; bits = 2;
    } else {
        vec3 mean = u_w_left * l.color + (1.0 - u_w_left) * r.color;
        bool left_near = l.z_middle <= r.z_middle;
        vec3 near_color = left_near ? l.color : r.color;
        int near_bit = left_near ? 1 : 2;
        float dz = abs(l.z_middle - r.z_middle);
        z = min(l.z_middle, r.z_middle);
#if BLEND_SOFT
        float t = clamp(1.0 - dz / u_z_threshold, 0.0, 1.0);
        c = near_color + (mean - near_color) * t;
        bits = t > 0.0 ? 3 : near_bit;
#else
        if (dz > u_z_threshold) {
            c = near_color; bits = near_bit;
        } else {
            c = mean; bits = 3;
        }
#endif
    }
    o_color = vec4(c / 255.0, 1.0);
    o_depth = z;
    o_sources = float(bits) / 255.0;
}
