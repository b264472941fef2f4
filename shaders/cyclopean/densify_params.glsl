// cyclopean/densify's interface, the same text for GL and Vulkan: the std140 parameter block
// (binding 0) mirrored by `DensifyParams` in src/cyclopean/densify.rs, the constants of its rule
// (held against the Rust ones by a test), and one eye's disparity and colour (bindings 1, 2),
// rows in memory order.
layout(std140, binding = 0) PARAM_BLOCK DensifyParams {
    ivec2 u_size;     // W, H of the eye
    int u_radius;     // farthest a walk goes, pixels (Chebyshev)
    uint u_filled;    // the flag filled disparities carry
    float u_sign;     // the match lies at x + u_sign (d - u_offset): -1 left eye, +1 right
    float u_offset;   // the offset disparities are stored with
};
layout(binding = 1) uniform sampler2D u_disparity;  // R32F disparity (+ offset), 0 = unknown
layout(binding = 2) uniform sampler2D u_color;      // RGBA8 colour of the eye

// Colour distance (sum over r, g, b, levels) at which a candidate's weight has fallen to 1/4.
const uint COLOUR_SOFTNESS = 24u;
// The weighted quantile taken, percent: low, towards the background side.
const uint QUANTILE_PERCENT = 15u;
// The quantile among candidates that put the pixel outside the other eye's frame, percent: no
// occluder hid such a pixel, so no lean to the background.
const uint OUT_OF_FRAME_PERCENT = 50u;
