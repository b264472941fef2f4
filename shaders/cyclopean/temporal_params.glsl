// cyclopean/temporal_*'s parameter block, the same text for GL and Vulkan, mirrored by
// `TemporalParams` in src/cyclopean/temporal.rs: the previous middle view's camera (h) and the
// current one (m), and the accumulation's rule.
layout(std140, binding = 0) PARAM_BLOCK TemporalParams {
    mat4 u_inv_view_h;
    mat4 u_ray_basis_h;
    mat4 u_view_proj_m;
    mat4 u_view_m;
    ivec2 u_size_h;          // W, H of the previous view
    ivec2 u_size_m;          // W, H of the current view
    uint u_stage;            // reprojection: 0 nearest distance, 1 its texel (the shader is
                             // compiled per stage, WINNER_STAGE; kept for the layout and tools)
    int u_flip_rows;         // 1: memory rows are bottom-up (texel indices count top-down rows)
    float u_alpha;           // weight of the current frame where both agree (1: no blending)
    float u_depth_tolerance; // relative distance difference above which the history is rejected
};

// temporal.rs FROM_HISTORY, the source bit of pixels the history filled (the twin test compares
// the source bits exactly).
const uint FROM_HISTORY = 4u;
