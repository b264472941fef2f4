// Edge pass of the splat-gather method (src/cyclopean/splat.rs): one invocation per pixel the
// gather draw listed (cyclopean/edge_list.glsl). A camera pixel integrates its footprint: where
// a depth edge crosses it, its colour mixes both surfaces. Rectified views move edges only along
// x (their mixing along y is already in the eyes' pixels), so at an edge the colour is the mean
// of the centre and two samples at +-1/3 px along x (a 3-tap box over the pixel), over those an
// eye answers; where the three see one surface, the centre alone (the gather draw's colour,
// left as written). Same inputs and functions as the gather draw, so the centre is the same.

layout(local_size_x = EDGE_GROUP_SIZE_INT) in;
layout(rgba8, STORAGE_IMAGE(0)) writeonly uniform image2D u_color_out;

// The mixed colour of listed pixel p, written where its samples see more than one surface.
void mix_edge(ivec2 p) {
    vec2 centre = vec2(p) + 0.5;
    Neighbourhood nl = neighbourhood(u_splat_l, p);
    Neighbourhood nr = neighbourhood(u_splat_r, p);
    Merged m = shade(centre, nl.cand, nr.cand);
    vec3 sum = m.color;
    float n = 1.0;
    float d_lo = u_parallax_px / m.z;
    float d_hi = d_lo;
    for (int k = 0; k < 2; ++k) {
        Merged s = shade(centre + vec2(k == 0 ? -SUBSAMPLE : SUBSAMPLE, 0.0), nl.cand, nr.cand);
        if (s.valid) {
            sum += s.color;
            n += 1.0;
            float d = u_parallax_px / s.z;
            d_lo = min(d_lo, d);
            d_hi = max(d_hi, d);
        }
    }
    if (d_hi - d_lo > u_tolerance_px) {
        imageStore(u_color_out, p, vec4(sum / n / 255.0, 1.0));
    }
}

void main() {
    // Over the whole list whatever the number of work groups (capped at EDGE_MAX_GROUPS).
    uint stride = gl_NumWorkGroups.x * EDGE_GROUP_SIZE;
    for (uint i = gl_GlobalInvocationID.x; i < edge_count; i += stride) {
        uint xy = edge_pixel[i];
        mix_edge(ivec2(int(xy & 0xFFFFu), int(xy >> 16)));
    }
}
