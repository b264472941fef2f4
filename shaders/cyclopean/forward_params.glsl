// cyclopean/forward's interface, the same text for GL and Vulkan and for both stages: the
// std140 parameter block (binding 0) mirrored by `ForwardParams` in src/cyclopean/forward.rs,
// one per eye's draw, and the eye's images (bindings 1..3).
layout(std140, binding = 0) PARAM_BLOCK ForwardParams {
    mat4 u_inv_view_e;
    mat4 u_ray_basis_e;
    mat4 u_view_proj_e;
    mat4 u_view_m;
    mat4 u_view_proj_m;
    mat4 u_ray_basis_vp_m;  // world ray basis of the middle view-projection (src/camera/rays.rs)
    vec3 u_middle_centre;
    float u_expand_px;
    vec2 u_size_m;
    ivec2 u_eye_size;
    // Relative push away from the middle camera for this eye's depth test only: where both
    // eyes saw the same surface their depths differ by float rounding, which the depth buffer
    // would resolve differently under each convention; the pushed eye wins only when nearer by
    // more.
    float u_depth_bias;
    int u_eye_bit;
};
layout(binding = 1) uniform sampler2D u_color;     // RGBA8 eye colour, memory order
layout(binding = 2) uniform sampler2D u_distance;  // R32F eye view distance, memory order (0 = invalid)
layout(binding = 3) uniform usampler2D u_tris;     // R32UI kept-triangle codes, TRI_TEX_WIDTH wide
