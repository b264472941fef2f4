// Boundary triangles of the grid mesh (a corner touches a dropped triangle or the outer ring),
// by vertex pulling: vertex 3t + k is corner k of triangle t, whose code (cell << 1 | tri) comes
// from u_tris. Each vertex sees its whole triangle, so it pushes itself out by u_expand_px
// (window pixels) along the corner's bisector; the fragment shader then keeps exactly the
// closed triangle, so coverage does not depend on the fill rule or the row order.
//
// Same pose: a source pixel (u, v) projects to the same target pixel whatever its depth, so
// corners are projected with Z = 1 through the target projection (w = 1: the map is affine)
// and only the depth-test value uses the corner's metric Z.

layout(binding = 5) uniform usampler2D u_tris;  // R32UI kept-triangle codes, TRI_TEX_WIDTH wide

flat out ivec3 v_cell;  // cell i, j and triangle (0 = tri1, 1 = tri2)

vec2 corner_ndc(ivec2 c) {
    vec2 uv = vec2(vertex_pos(c.x, u_src_size.x), vertex_pos(c.y, u_src_size.y));
    vec4 clip = u_clip_from_target * vec4((uv - u_src_k.zw) / u_src_k.xy, 1.0, 1.0);
    return clip.xy / clip.w;
}

void main() {
    ivec2 c;
    int tri, k;
    ivec2 corners[3];
    pulled_triangle(u_tris, u_src_size.x + 1, c, tri, corners, k);
    v_cell = ivec3(c, tri);

    vec2 half_size = 0.5 * u_dst_size;
    vec2 w0 = corner_ndc(corners[k]) * half_size;
    vec2 wn = corner_ndc(corners[(k + 1) % 3]) * half_size;
    vec2 wp = corner_ndc(corners[(k + 2) % 3]) * half_size;
    vec2 w;
    pushed_out_corner(w0, wn, wp, u_expand_px, w);
    float z = vertex_depth(corners[k]);
    gl_Position = vec4(w / half_size, u_clip_z.x + u_clip_z.y / z, 1.0);
}
