// Gather draw of the splat-gather method (src/cyclopean/splat.rs), after the splat: every
// pixel's centre sample (cyclopean/splat_gather.glsl), and the list of the pixels a depth edge
// may cross (cyclopean/edge_list.glsl), which splat_edges.comp then mixes over the pixel's
// width. Two passes rather than an `if` here: llvmpipe executes both sides of every branch for
// every pixel (the `if` cost 40 % of the frame on the built-in scene, 0.3 % of whose pixels are
// at edges), and on SIMT GPUs no warp waits on a few edge lanes.

layout(location = 0) out vec4 o_color;
layout(location = 1) out float o_depth;
layout(location = 2) out float o_sources;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    Neighbourhood nl = neighbourhood(u_splat_l, p);
    Neighbourhood nr = neighbourhood(u_splat_r, p);
    Merged m = shade(gl_FragCoord.xy, nl.cand, nr.cand);
    if (m.valid && (nl.edge || nr.edge)) {
        uint i = atomicAdd(edge_count, 1u);
        if (i % EDGE_GROUP_SIZE == 0u && i / EDGE_GROUP_SIZE < EDGE_MAX_GROUPS) {
            atomicAdd(edge_groups, 1u);
        }
        edge_pixel[i] = uint(p.y) << 16 | uint(p.x);
    }
    o_color = vec4(m.color / 255.0, 1.0);
    o_depth = m.z;
    o_sources = float(m.bits) / 255.0;
}
