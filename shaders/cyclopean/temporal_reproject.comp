// History reprojection of the temporal accumulation (src/cyclopean/temporal.rs; f64 twin:
// TemporalAccumulator): each texel of the previous middle view an eye rendered (not one the
// history filled: see temporal.rs on why a fill is carried one frame only) moves with its distance
// into the current middle camera, to the pixel whose centre its one-pixel footprint covers (the
// floor of its window position), as splat.comp moves an eye's texels.
// Stage 0 keeps each pixel's nearest distance (atomic min on the float bits: positive floats
// order like their bit patterns). Stage 1 runs the same arithmetic in the same program, so its
// distances are those bits exactly, and keeps the smallest top-down texel index among the texels
// at that distance: the twin's rule, where the first texel in row order wins a tie.

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 1) uniform sampler2D u_hist_depth;     // R32F previous distance, memory order
layout(binding = 2) uniform usampler2D u_hist_sources;  // R8UI previous source bits, 0 = hole
layout(r32ui, STORAGE_IMAGE(0)) uniform uimage2D u_nearest;  // cleared to 0xFFFFFFFF
layout(r32ui, STORAGE_IMAGE(1)) uniform uimage2D u_winner;   // cleared to 0xFFFFFFFF

// Texel t was rendered by an eye (not filled from the history) at a usable distance.
bool rendered(ivec2 t) {
    uint source = texelFetch(u_hist_sources, t, 0).r;
    float z = texelFetch(u_hist_depth, t, 0).r;
    return source != 0u && source != FROM_HISTORY && z > 0.0 && !isinf(z);
}

void main() {
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(t, u_size_h))) {
        return;
    }
    if (!rendered(t)) {
        return;
    }
    float z = texelFetch(u_hist_depth, t, 0).r;
    // Not an edge: every 4-neighbour in the image rendered and none farther than the tolerance
    // (temporal.rs `carried`: an edge texel would fill the background a disocclusion uncovers).
    float far = z * (1.0 + u_depth_tolerance);
    const ivec2 steps[4] = ivec2[4](ivec2(-1, 0), ivec2(1, 0), ivec2(0, -1), ivec2(0, 1));
    for (int k = 0; k < 4; ++k) {
        ivec2 n = t + steps[k];
        if (all(greaterThanEqual(n, ivec2(0))) && all(lessThan(n, u_size_h))
            && (!rendered(n) || texelFetch(u_hist_depth, n, 0).r > far)) {
            return;
        }
    }
    vec3 ray = view_ray(u_ray_basis_h, ndc_of_pixel(vec2(t), vec2(u_size_h)));
    vec4 world = vec4(transform_point(u_inv_view_h, ray * z), 1.0);
    vec4 clip = u_view_proj_m * world;
    if (!(clip.w > 0.0)) {
        return;
    }
    vec2 px = floor(window_of_clip(clip, vec2(u_size_m)));
    float zm = -(u_view_m * world).z;
    if (any(lessThan(px, vec2(0.0))) || any(greaterThanEqual(px, vec2(u_size_m))) || !(zm > 0.0) || isinf(zm)) {
        return;
    }
    uint bits = floatBitsToUint(zm);
    // The stage is compiled in (WINNER_STAGE), not read from u_stage: see ProgramKind.
#if WINNER_STAGE == 0
    imageAtomicMin(u_nearest, ivec2(px), bits);
#else
    if (imageLoad(u_nearest, ivec2(px)).r == bits) {
        int row = u_flip_rows != 0 ? u_size_h.y - 1 - t.y : t.y;
        imageAtomicMin(u_winner, ivec2(px), uint(row * u_size_h.x + t.x));
    }
#endif
}
