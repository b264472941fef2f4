// Fragment-stage helpers of the refocus grid: the closed triangle test, exact depth and f32
// bilinear colour.

// Per target column / image row (grid.rs axis_lookup): [cell, local coordinate in it, 1 if on
// the cell's left/top border, -]; cell < 0 outside the mesh. The same-pose map from target pixel
// to source point is separable, so it is located in f64 on the CPU: f32 at u ~ 600 px would be
// off by 6e-5 px, and per-pixel doubles cost llvmpipe more than the rest of the pass.

// The mask attachment is R8 (normalised): 1/255 stores the byte 1, the in-memory mask's
// "valid", so its readback is the mask as it is, with no per-pixel conversion.
const float MASK_SET = 1.0 / 255.0;

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
    return inside_closed_triangle(ab, tri, CELL_EPS);
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

// One textureGather fetches a cell's 2x2 footprint: cell c spans source pixels c - 1 .. c
// (clamp-to-edge gives the border ring). The gather point is the footprint's centre, half a
// texel away from any footprint decision. Gather order: x (0,1), y (1,1), z (1,0), w (0,0).
vec2 cell_gather_point(ivec2 c) {
    return vec2(c) / vec2(u_src_size);
}

// Source depths at the cell's corners, as (z00, z10, z01, z11).
vec4 cell_depths(ivec2 c) {
    vec4 g = textureGather(u_src_depth, cell_gather_point(c), 0);
    return vec4(g.w, g.z, g.x, g.y);
}

// Bilinear source colour over cell c at local weights t, in f32 (fixed-function filtering has
// only ~8 bits of weight precision; gathers return the texels exactly).
vec3 cell_rgb(ivec2 c, vec2 t) {
    vec2 p = cell_gather_point(c);
    vec4 r = textureGather(u_src_rgb, p, 0);
    vec4 g = textureGather(u_src_rgb, p, 1);
    vec4 b = textureGather(u_src_rgb, p, 2);
    return bilinear(vec3(r.w, g.w, b.w), vec3(r.z, g.z, b.z), vec3(r.x, g.x, b.x), vec3(r.y, g.y, b.y), t);
}
