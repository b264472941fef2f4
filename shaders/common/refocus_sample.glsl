// Fragment-stage helpers of the refocus grid: the exact source point of a pixel, the closed
// triangle test, exact depth and f32 bilinear colour.

// Same-pose mapping target pixel -> source pixel, u = cx + (u' - cx') fx / fx', evaluated in
// double: in f32 a coordinate near 600 px carries ~6e-5 px of error, which across a cell with a
// 5 % depth step is 1.5e-6 relative depth error. Doubles arrive as hi + lo float pairs.
uniform vec2 u_src_c_hi, u_src_c_lo;  // cx, cy
uniform vec2 u_dst_c_hi, u_dst_c_lo;  // cx', cy'
uniform vec2 u_ratio_hi, u_ratio_lo;  // fx / fx', fy / fy'
uniform int u_dst_height;

dvec2 same_pose_source_point() {
#if ROWS_TOP_DOWN
    double v_dst = double(gl_FragCoord.y) - 0.5;
#else
    double v_dst = double(u_dst_height) - double(gl_FragCoord.y) - 0.5;
#endif
    dvec2 dst = dvec2(double(gl_FragCoord.x) - 0.5, v_dst);
    dvec2 src_c = dvec2(u_src_c_hi) + dvec2(u_src_c_lo);
    dvec2 dst_c = dvec2(u_dst_c_hi) + dvec2(u_dst_c_lo);
    dvec2 ratio = dvec2(u_ratio_hi) + dvec2(u_ratio_lo);
    return src_c + (dst - dst_c) * ratio;
}

// Cell-local coordinates (a, b) of source point uv in cell c (small, so f32 is enough).
vec2 cell_local(ivec2 c, dvec2 uv) {
    dvec2 p0 = dvec2(vertex_pos(c.x, u_src_size.x), vertex_pos(c.y, u_src_size.y));
    dvec2 p1 = dvec2(vertex_pos(c.x + 1, u_src_size.x), vertex_pos(c.y + 1, u_src_size.y));
    return vec2((uv - p0) / (p1 - p0));
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

vec3 bilinear_rgb(dvec2 uv) {
    dvec2 f0 = floor(uv);
    return bilinear_rgb_at(ivec2(f0), vec2(uv - f0));
}
