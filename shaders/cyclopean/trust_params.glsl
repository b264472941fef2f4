// cyclopean/trust's interface, the same text for GL and Vulkan: the std140 parameter block
// (binding 0) mirrored by `TrustParams` in src/stereo/trust.rs, the constants of its rule (held
// against the Rust ones by a test), and one eye's semi-global and census disparities and colour
// (bindings 1-3), rows in memory order.
layout(std140, binding = 0) PARAM_BLOCK TrustParams {
    ivec2 u_size;  // W, H of the eye
    ivec2 u_pad;
};
layout(binding = 1) uniform sampler2D u_semi_global;  // R32F disparity (+ offset), 0 = unknown
layout(binding = 2) uniform sampler2D u_census;       // R32F disparity (+ offset), 0 = unknown
layout(binding = 3) uniform sampler2D u_color;        // RGBA8 colour of the eye

// Largest difference (px) at which the two matchers agree.
const float AGREE_PX = 1.0;
// Largest grey range (r + g + b levels) of a flat census window.
const int FLAT_GREY = 20;
// The census window's half-width and half-height (7 x 5).
const int HALF_W = 3;
const int HALF_H = 2;
