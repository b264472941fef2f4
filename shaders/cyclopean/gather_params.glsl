// cyclopean/gather's interface, the same text for GL and Vulkan: the std140 parameter block
// (binding 0) mirrored by `GatherParams` in src/cyclopean/render.rs, and the eyes' images
// (bindings 1..4).
layout(std140, binding = 0) PARAM_BLOCK GatherParams {
    mat4 u_view_proj_l;
    mat4 u_inv_view_l;
    mat4 u_inv_proj_l;
    mat4 u_view_l;
    mat4 u_view_proj_r;
    mat4 u_inv_view_r;
    mat4 u_inv_proj_r;
    mat4 u_view_r;
    mat4 u_view_m;
    mat4 u_inv_view_m;
    mat4 u_ray_basis_m;  // pixel rays (src/camera/rays.rs), the same under every convention
    mat4 u_view_proj_m;
    mat4 u_ray_basis_l;  // the eyes' pixel rays (view-distance depth)
    mat4 u_ray_basis_r;
    vec2 u_size_m;
    float u_fixation;    // initial distance along the middle view axis
    float u_z_threshold;
    float u_w_left;      // weight of the left eye in blends (0.5 without a dominant eye)
    int u_steps;
};
layout(binding = 1) uniform sampler2D u_color_l;  // RGBA8, memory order
layout(binding = 2) uniform sampler2D u_color_r;
layout(binding = 3) uniform sampler2D u_depth_l;  // R32F: window depth or view distance (DEPTH_IS_DEVICE)
layout(binding = 4) uniform sampler2D u_depth_r;
