// reproject/shift's interface, the same text for GL and Vulkan: the std140 parameter block
// (binding 0) mirrored by `ShiftParams` in src/reproject/render.rs, and the sampled images
// (bindings 1..), in the order the pass description lists them.
layout(std140, binding = 0) PARAM_BLOCK ShiftParams {
    float u_a;        // shift model, pixels: column s at inverse depth q lands at s + a - b q
    float u_b;
    float u_alpha;    // q = alpha * stored + beta (DEPTH_MODE 1, 2)
    float u_beta;
    float u_q_min;    // inverse depth range of the frame
    float u_q_max;
    float u_tau_rel;
    int u_steps;
};
layout(binding = 1) uniform sampler2D u_color;  // RGBA8, memory order
layout(binding = 2) uniform sampler2D u_depth;  // R32F, raw stored value
