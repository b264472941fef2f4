// Holes of the middle view filled from the background side (fill.rs holds the f64 twin and the
// rule): a pixel no eye saw takes the colour and depth of the nearest valid pixel to its left or
// right along the row, whichever is farther (a disocclusion uncovers background, so the nearer
// foreground edge must not bleed into it), or, where both lie on one surface (depths within
// u_same_surface relative), their mix by distance. With neither found along the row, the
// column is searched the same way.
// Rendered pixels pass through unchanged; filled ones carry only u_filled.

layout(location = 0) out vec4 o_color;
layout(location = 1) out float o_depth;
layout(location = 2) out float o_sources;  // R8 normalised: bits / 255 stores the bits

// Steps to the nearest valid pixel from p along d (its position in q), 0: none before the
// image's edge.
int nearest_valid(ivec2 p, ivec2 d, out ivec2 q) {
    q = p;
    for (int k = 1; k <= max(u_size.x, u_size.y); ++k) {
        ivec2 c = p + k * d;
        if (any(lessThan(c, ivec2(0))) || any(greaterThanEqual(c, u_size))) {
            return 0;
        }
        if (texelFetch(u_sources, c, 0).r != 0u) {
            q = c;
            return k;
        }
    }
    return 0;
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
    ivec2 a, b;
    int da = nearest_valid(p, ivec2(-1, 0), a);
    int db = nearest_valid(p, ivec2(1, 0), b);
    if (da == 0 && db == 0) {
        da = nearest_valid(p, ivec2(0, -1), a);
        db = nearest_valid(p, ivec2(0, 1), b);
    }
    if (da == 0 && db == 0) {
        o_color = vec4(0.0);
        o_depth = 0.0;
        o_sources = 0.0;
        return;
    }
    o_sources = float(u_filled) / 255.0;
    if (da != 0 && db != 0) {
        float za = texelFetch(u_depth, a, 0).r;
        float zb = texelFetch(u_depth, b, 0).r;
        if (abs(za - zb) <= u_same_surface * max(za, zb)) {
            // One surface on both sides (a hole in it, not a disocclusion): interpolate.
            float t = float(da) / float(da + db);
            o_color = mix(texelFetch(u_color, a, 0), texelFetch(u_color, b, 0), t);
            o_depth = mix(za, zb, t);
            return;
        }
        if (za > zb) {
            db = 0;
        } else {
            da = 0;
        }
    }
    ivec2 q = da != 0 ? a : b;
    o_color = texelFetch(u_color, q, 0);
    o_depth = texelFetch(u_depth, q, 0).r;
}
