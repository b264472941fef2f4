// Fragment-stage helpers of the refocus grid: the closed triangle test, exact depth and f32
// bilinear colour.

// Per target column / image row (grid.rs axis_lookup): [cell, local coordinate in it, 1 if on
// the cell's left/top border, -]; cell < 0 outside the mesh. The same-pose map from target pixel
// to source point is separable, so it is located in f64 on the CPU: f32 at u ~ 600 px would be
// off by 6e-5 px, and per-pixel doubles cost llvmpipe more than the rest of the pass.
uniform sampler2D u_cols;  // RGBA32F, W' x 1
uniform sampler2D u_rows;  // RGBA32F, H' x 1
uniform int u_dst_height;

void pixel_lookups(out vec4 col, out vec4 row) {
#if ROWS_TOP_DOWN
    int y = int(gl_FragCoord.y);
#else
    int y = u_dst_height - 1 - int(gl_FragCoord.y);
#endif
    col = texelFetch(u_cols, ivec2(int(gl_FragCoord.x), 0), 0);
    row = texelFetch(u_rows, ivec2(y, 0), 0);
}

// Is local point ab inside triangle `tri` (0 = tri1, 1 = tri2), closed, within CELL_EPS?
bool inside_tri(vec2 ab, int tri) {
    if (tri == 0) {
        return ab.y >= -CELL_EPS && ab.x <= 1.0 + CELL_EPS && ab.x >= ab.y - CELL_EPS;
    }
    return ab.x >= -CELL_EPS && ab.y <= 1.0 + CELL_EPS && ab.y >= ab.x - CELL_EPS;
}

// View-space Z of the source surface at local point ab of triangle `tri`, whose corner depths
// are z (in the order tri1: v00 v10 v11, tri2: v00 v11 v01). 1/Z is affine over a planar
// triangle in the source image, so this is exact; ab is first projected onto the closed
// triangle so the weights stay convex and Z stays within the corners' range.
float tri_depth(vec2 ab, int tri, vec3 z) {
    vec3 w;
    if (tri == 0) {
        float a = clamp(ab.x, 0.0, 1.0);
        float b = clamp(ab.y, 0.0, a);
        w = vec3(1.0 - a, a - b, b);
    } else {
        float b = clamp(ab.y, 0.0, 1.0);
        float a = clamp(ab.x, 0.0, b);
        w = vec3(1.0 - b, a, b - a);
    }
    return 1.0 / dot(w, 1.0 / z);
}

// Bilinear source colour at continuous pixel coordinate uv (pixel centres at integers), in f32
// with texelFetch: fixed-function filtering has only ~8 bits of weight precision.
vec3 bilinear_rgb_at(ivec2 i0, vec2 t) {
    ivec2 hi = u_src_size - 1;
    vec3 c00 = texelFetch(u_src_rgb, clamp(i0, ivec2(0), hi), 0).rgb;
    vec3 c10 = texelFetch(u_src_rgb, clamp(i0 + ivec2(1, 0), ivec2(0), hi), 0).rgb;
    vec3 c01 = texelFetch(u_src_rgb, clamp(i0 + ivec2(0, 1), ivec2(0), hi), 0).rgb;
    vec3 c11 = texelFetch(u_src_rgb, clamp(i0 + ivec2(1, 1), ivec2(0), hi), 0).rgb;
    vec3 top = mix(c00, c10, t.x);
    vec3 bottom = mix(c01, c11, t.x);
    return mix(top, bottom, t.y);
}
