// Holes of the middle view filled in two dimensions from the background layer (fill.rs holds the
// f64 twin and the rule): a pixel no eye saw walks the 16 directions of directions.glsl to the
// first valid pixel in each; the candidates sorted far to near, the background layer is the
// farthest one and every next one within u_same_surface (relative) of the one before it (a chain:
// a slanted surface stays one layer, an occluder's edge starts another); the pixel takes that
// layer's colour and depth, weighted by 1 / distance^2. So a disocclusion takes what lies behind
// the occluder, and a hole in one surface is interpolated across it in 2-D, without row streaks.
// Candidates count only up to u_reach (2) times the row's far end: a walk along a thin hole
// that meets a far surface beyond it is none of the hole's sides.
// In a border strip (the row runs off the image with no rendered pixel: beyond both eyes' frames,
// nothing uncovered) the layer is the chain of the nearest candidate instead of the farthest.
// Rendered pixels pass through unchanged; filled ones carry only u_filled.

layout(location = 0) out vec4 o_color;
layout(location = 1) out float o_depth;
layout(location = 2) out float o_sources;  // R8 normalised: bits / 255 stores the bits

bool walk_stops_at(ivec2 q) {
    return texelFetch(u_sources, q, 0).r != 0u;
}

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    uint bits = texelFetch(u_sources, p, 0).r;
    if (bits != 0u) {
        o_color = texelFetch(u_color, p, 0);
        o_depth = texelFetch(u_depth, p, 0).r;
        o_sources = float(bits) / 255.0;
        return;
    }
    float z[16];
    int r[16];
    ivec2 at[16];
    int n = 0;
    int radius = max(u_size.x, u_size.y);
    // The row (directions 0 and 8: +x, -x): off the image with no rendered pixel either way is a
    // border strip; inside, candidates count up to u_reach times its span.
    // The row's two walks are the loop's directions 0 and 8: walked once, their hits reused.
    ivec2 q_right, q_left, q;
    int r_right = first_along(p, DIRECTIONS[0], u_size, radius, q_right);
    int r_left = first_along(p, DIRECTIONS[8], u_size, radius, q_left);
    bool border_strip = r_right == 0 || r_left == 0;
    int reach = border_strip ? radius : u_reach * max(r_right, r_left);
    for (int i = 0; i < DIRECTION_COUNT; ++i) {
        int r_q;
        if (i == 0) {
            r_q = r_right;
            q = q_right;
        } else if (i == 8) {
            r_q = r_left;
            q = q_left;
        } else {
            r_q = first_along(p, DIRECTIONS[i], u_size, radius, q);
        }
        if (r_q == 0 || r_q > reach) {
            continue;
        }
        float zq = texelFetch(u_depth, q, 0).r;
        // Insertion far to near; equal depths keep direction order (the twin's stable sort).
        int j = n;
        while (j > 0 && z[j - 1] < zq) {
            z[j] = z[j - 1];
            r[j] = r[j - 1];
            at[j] = at[j - 1];
            --j;
        }
        z[j] = zq;
        r[j] = r_q;
        at[j] = q;
        ++n;
    }
    if (n == 0) {
        o_color = vec4(0.0);
        o_depth = 0.0;
        o_sources = 0.0;
        return;
    }
    // The layer's seed: the farthest candidate, or in a border strip the first of the nearest.
    int seed = 0;
    if (border_strip) {
        for (int i = 1; i < n; ++i) {
            if (r[i] < r[seed]) {
                seed = i;
            }
        }
    }
    int lo = seed;
    while (lo > 0 && z[lo - 1] - z[lo] <= u_same_surface * z[lo - 1]) {
        --lo;
    }
    int hi = seed + 1;
    while (hi < n && z[hi - 1] - z[hi] <= u_same_surface * z[hi - 1]) {
        ++hi;
    }
    vec4 color = vec4(0.0);
    float depth = 0.0;
    float total = 0.0;
    for (int i = lo; i < hi; ++i) {
        float w = 1.0 / float(r[i] * r[i]);
        color += w * texelFetch(u_color, at[i], 0);
        depth += w * z[i];
        total += w;
    }
    o_color = color / total;
    o_depth = depth / total;
    o_sources = float(u_filled) / 255.0;
}
