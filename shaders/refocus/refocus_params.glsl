// The refocus passes' interface, the same text for GL and Vulkan and for every stage of the
// three programs: the std140 parameter block (binding 0) mirrored by `RefocusParams` in
// src/refocus/render.rs, and the images every pass samples (bindings 1..4). The full-screen
// pass adds its coverage flags and the boundary pass its triangle codes, both at binding 5.
layout(std140, binding = 0) PARAM_BLOCK RefocusParams {
    mat4 u_clip_from_target;  // target projection (OpenCV view space, see projection.rs)
    vec4 u_src_k;             // fx, fy, cx, cy of the source
    ivec2 u_src_size;         // W, H
    vec2 u_clip_z;            // z_ndc = x + y / Z under the conventions (convention.rs)
    vec2 u_dst_size;          // W', H'
    int u_dst_height;
    float u_expand_px;        // boundary triangles' push-out, window pixels
};
layout(binding = 1) uniform sampler2D u_src_rgb;    // RGBA8 source colour, row 0 = top of the image
layout(binding = 2) uniform sampler2D u_src_depth;  // R32F source view-space Z in metres, row 0 = top
layout(binding = 3) uniform sampler2D u_cols;       // RGBA32F, W' x 1 (grid.rs axis_lookup)
layout(binding = 4) uniform sampler2D u_rows;       // RGBA32F, H' x 1
