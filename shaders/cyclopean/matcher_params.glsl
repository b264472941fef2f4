// cyclopean/matcher's interface, one text for GL and Vulkan and for every stage of the census
// stereo matcher (src/cyclopean/matcher/mod.rs holds the design and the constants' Rust
// values, which a unit test holds this file to; reference.rs is the CPU twin). One invocation
// per pixel, rows in memory order = the images' top-down rows (the rule is symmetric in y).
layout(local_size_x = 8, local_size_y = 8) in;
layout(std140, binding = 0) PARAM_BLOCK MatcherParams {
    ivec2 u_size;         // W, H of both images
    int u_max_disparity;  // disparities 0..=u_max_disparity are searched
    int u_first_d;        // the chunk's first disparity (even)
    int u_pairs;          // words per pixel in the chunk buffers: disparity pairs, 16-bit lanes
    // The semi-global matcher's stages (matcher_sgm_*.comp) only:
    int u_window;         // disparities each pixel of the level searches
    ivec2 u_direction;    // the path stage's step (dx, dy)
    ivec2 u_other_size;   // the finer level (downsample) or the coarser one (cost; 0 = none)
    int u_final;          // winner stage: 1 at the pair's own level (winners), 0 (guides)
    int u_pad;
};

const int CENSUS_HALF_W = 3;
const int CENSUS_HALF_H = 2;
const int BOX_RADIUS = 4;
const uint MEAN_SHIFT = 8u;
const uint UNIQUENESS_PERCENT = 5u;
const float LR_TOLERANCE_PX = 1.0;
// A 16-bit cost lane holding no cost: the disparity cannot exist at the pixel, or none was
// offered yet (means are at most 34 << MEAN_SHIFT, well below).
const uint NO_LANE = 0xffffu;

int pixels() {
    return u_size.x * u_size.y;
}

// The invocation's pixel, or (-1, -1) outside the image.
ivec2 this_pixel() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    return any(greaterThanEqual(p, u_size)) ? ivec2(-1) : p;
}

// Rust's f32::round: to the nearest integer, halves away from zero (GLSL's round leaves the
// halves to the implementation). r + 0.5 is exact below 2^22, so the comparisons are exact.
float round_half_away(float v) {
    float r = floor(v);
    float half_up = r + 0.5;
    return (v > half_up || (v == half_up && v >= 0.0)) ? r + 1.0 : r;
}
