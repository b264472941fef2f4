// cyclopean/fill's interface, the same text for GL and Vulkan: the std140 parameter block
// (binding 0) mirrored by `FillParams` in src/cyclopean/fill.rs, and the middle view it fills
// (bindings 1..3), rows in memory order.
layout(std140, binding = 0) PARAM_BLOCK FillParams {
    ivec2 u_size;     // W, H of the middle view
    uint u_filled;    // the source bit filled pixels carry (fill.rs FILLED)
    float u_same_surface;  // relative depth difference below which both sides are one surface
    int u_reach;      // candidates count up to this multiple of the row's span (fill.rs REACH)
};
layout(binding = 1) uniform sampler2D u_color;     // RGBA8 middle colour
layout(binding = 2) uniform sampler2D u_depth;     // R32F middle distance, 0 = none
layout(binding = 3) uniform usampler2D u_sources;  // R8UI source bits, 0 = hole
