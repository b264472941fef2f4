// The refocus grid (see src/refocus/grid.rs): vertex column i sits at source u = -0.5, 0, 1,
// .., W-1, W-0.5 and carries the depth of pixel clamp(i - 1, 0, W - 1). Cell (i, j) holds
// tri1 = v00 v10 v11 (local a >= b) and tri2 = v00 v11 v01 (local a <= b).

uniform sampler2D u_src_rgb;    // RGBA8 source colour, row 0 = top of the image
uniform sampler2D u_src_depth;  // R32F source view-space Z in metres, row 0 = top
uniform ivec2 u_src_size;       // W, H
uniform vec4 u_src_k;           // fx, fy, cx, cy of the source

// Closed-triangle tolerance in cell units: pixel centres exactly on an edge are covered by
// both neighbours whatever the rasteriser's fill rule or the row order. 1e-3 is well above
// the f32 error of the source coordinates (~1e-5 px) and widens coverage by at most 1e-3 px.
const float CELL_EPS = 1e-3;

float vertex_pos(int i, int n) {
    return i <= 0 ? -0.5 : (i > n ? float(n) - 0.5 : float(i - 1));
}

float vertex_depth(ivec2 c) {
    return texelFetch(u_src_depth, clamp(c - 1, ivec2(0), u_src_size - 1), 0).r;
}

// Cell-local coordinates (a, b) of source point uv in cell c.
vec2 cell_local(ivec2 c, vec2 uv) {
    vec2 p0 = vec2(vertex_pos(c.x, u_src_size.x), vertex_pos(c.y, u_src_size.y));
    vec2 p1 = vec2(vertex_pos(c.x + 1, u_src_size.x), vertex_pos(c.y + 1, u_src_size.y));
    return (uv - p0) / (p1 - p0);
}

// Is local point ab inside triangle `tri` (0 = tri1, 1 = tri2), closed, within CELL_EPS?
bool inside_tri(vec2 ab, int tri) {
    if (tri == 0) {
        return ab.y >= -CELL_EPS && ab.x <= 1.0 + CELL_EPS && ab.x >= ab.y - CELL_EPS;
    }
    return ab.x >= -CELL_EPS && ab.y <= 1.0 + CELL_EPS && ab.y >= ab.x - CELL_EPS;
}

// Bilinear source colour at continuous pixel coordinate uv (pixel centres at integers), in f32
// with texelFetch: fixed-function filtering has only ~8 bits of weight precision.
vec3 bilinear_rgb(vec2 uv) {
    vec2 f0 = floor(uv);
    vec2 t = uv - f0;
    ivec2 i0 = ivec2(f0);
    ivec2 hi = u_src_size - 1;
    vec3 c00 = texelFetch(u_src_rgb, clamp(i0, ivec2(0), hi), 0).rgb;
    vec3 c10 = texelFetch(u_src_rgb, clamp(i0 + ivec2(1, 0), ivec2(0), hi), 0).rgb;
    vec3 c01 = texelFetch(u_src_rgb, clamp(i0 + ivec2(0, 1), ivec2(0), hi), 0).rgb;
    vec3 c11 = texelFetch(u_src_rgb, clamp(i0 + ivec2(1, 1), ivec2(0), hi), 0).rgb;
    vec3 top = mix(c00, c10, t.x);
    vec3 bottom = mix(c01, c11, t.x);
    return mix(top, bottom, t.y);
}
