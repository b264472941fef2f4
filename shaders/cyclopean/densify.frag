// Dense disparities (densify.rs holds the f64 twin and the rule): an unknown disparity takes,
// from the first known pixel along each of 16 directions, the weighted 15 % quantile of their
// disparities, weights falling with the colour difference and the distance. The low quantile
// leans to the background side (an occluded pixel belongs to the surface behind its occluder);
// the colour weights keep a textureless region on its own surface. Integer weights and a
// comparison sort: the GPU picks the twin's candidate, bit for bit.
// Known disparities pass through with flag 0; filled ones carry u_filled.

layout(location = 0) out float o_disparity;
layout(location = 1) out float o_filled;  // R8 normalised: bits / 255 stores the bits

// Whether stored disparity v at column x has its match outside the other eye's frame.
bool outside(float x, float v) {
    float partner = x + u_sign * (v - u_offset);
    return partner < 0.0 || partner > float(u_size.x - 1);
}

bool walk_stops_at(ivec2 q) {
    return texelFetch(u_disparity, q, 0).r > 0.0;
}

uvec3 colour(ivec2 q) {
    return uvec3(round(texelFetch(u_color, q, 0).rgb * 255.0));
}

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    float own = texelFetch(u_disparity, p, 0).r;
    if (own > 0.0) {
        o_disparity = own;
        o_filled = 0.0;
        return;
    }
    uvec3 c = colour(p);
    float v[16];
    uint w[16];
    bool leaves[16];
    int n = 0;
    for (int i = 0; i < DIRECTION_COUNT; ++i) {
        ivec2 q;
        int r = first_along(p, DIRECTIONS[i], u_size, u_radius, q);
        if (r == 0) {
            continue;
        }
        uvec3 cq = colour(q);
        uvec3 diff = max(c, cq) - min(c, cq);
        uint s = COLOUR_SOFTNESS + diff.r + diff.g + diff.b;
        float value = texelFetch(u_disparity, q, 0).r;
        uint weight = ((1u << 30) / (s * s)) / uint(r);
        // Insertion by disparity; equal ones keep direction order (as the twin's stable sort).
        int j = n;
        while (j > 0 && v[j - 1] > value) {
            v[j] = v[j - 1];
            w[j] = w[j - 1];
            leaves[j] = leaves[j - 1];
            --j;
        }
        v[j] = value;
        w[j] = weight;
        leaves[j] = outside(float(p.x), value);
        ++n;
    }
    if (n == 0) {
        o_disparity = 0.0;
        o_filled = 0.0;
        return;
    }
    // Candidates that put p's match outside the other eye's frame explain its being unknown
    // without an occluder: those alone (the others' weights zeroed), and no lean to the
    // background.
    bool any_leaves = false;
    for (int i = 0; i < n; ++i) {
        any_leaves = any_leaves || leaves[i];
    }
    uint percent = QUANTILE_PERCENT;
    if (any_leaves) {
        percent = OUT_OF_FRAME_PERCENT;
        for (int i = 0; i < n; ++i) {
            if (!leaves[i]) {
                w[i] = 0u;
            }
        }
    }
    uint total = 0u;
    for (int i = 0; i < n; ++i) {
        total += w[i];
    }
    uint running = 0u;
    int pick = n - 1;
    for (int i = 0; i < n; ++i) {
        running += w[i];
        if (w[i] > 0u && running * 100u >= total * percent) {
            pick = i;
            break;
        }
    }
    o_disparity = v[pick];
    o_filled = float(u_filled) / 255.0;
}
