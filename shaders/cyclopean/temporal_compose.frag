// The accumulated middle view (src/cyclopean/temporal.rs; f64 twin: TemporalAccumulator::push):
// where the reprojected history landed, a pixel the current frame rendered blends with it if
// both lie within u_depth_tolerance (relative) of each other and keeps its own colour otherwise;
// a hole takes the history's colour and distance and the source bit FROM_HISTORY. Pixels no
// history texel reached pass through unchanged.

layout(location = 0) out vec4 o_color;
layout(location = 1) out float o_depth;
layout(location = 2) out float o_sources;  // R8 normalised: bits / 255 stores the bits

layout(binding = 1) uniform sampler2D u_color;        // RGBA8 current colour, memory order
layout(binding = 2) uniform sampler2D u_depth;        // R32F current distance, 0 = none
layout(binding = 3) uniform usampler2D u_sources;     // R8UI current source bits, 0 = hole
layout(binding = 4) uniform sampler2D u_hist_color;   // RGBA8 previous colour, memory order
layout(binding = 5) uniform usampler2D u_nearest;     // reprojected distance bits, all ones = none
layout(binding = 6) uniform usampler2D u_winner;      // its texel, top-down index, all ones = none

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 cur = texelFetch(u_color, p, 0);
    float cz = texelFetch(u_depth, p, 0).r;
    uint bits = texelFetch(u_sources, p, 0).r;
    uint winner = texelFetch(u_winner, p, 0).r;
    o_color = cur;
    o_depth = cz;
    o_sources = float(bits) / 255.0;
    if (winner == 0xFFFFFFFFu) {
        return;
    }
    float hz = uintBitsToFloat(texelFetch(u_nearest, p, 0).r);
    int row = int(winner / uint(u_size_h.x));
    ivec2 q = ivec2(int(winner % uint(u_size_h.x)), u_flip_rows != 0 ? u_size_h.y - 1 - row : row);
    vec4 hist = texelFetch(u_hist_color, q, 0);
    if (bits != 0u && cz > 0.0) {
        if (abs(hz - cz) <= u_depth_tolerance * cz) {
            o_color = vec4(mix(hist.rgb, cur.rgb, u_alpha), 1.0);
        }
    } else {
        o_color = hist;
        o_depth = hz;
        o_sources = float(FROM_HISTORY) / 255.0;
    }
}
