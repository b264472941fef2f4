// Grid mesh by vertex pulling: vertex 3t + k is corner k of kept triangle t, whose code
// (cell << 1 | tri) comes from u_tris. Each vertex sees its whole triangle, so it can push
// itself out by u_expand_px (window pixels) along the corner's bisector; the fragment shader
// then keeps exactly the closed triangle. Coverage so no longer depends on the fill rule.

uniform usampler2D u_tris;          // R32UI kept-triangle codes, TRI_TEX_WIDTH wide
uniform mat4 u_target_from_source;  // view transform (identity for a same-pose refocus)
uniform mat4 u_clip_from_target;    // target projection (OpenCV view space, see projection.rs)
uniform vec2 u_dst_size;
uniform float u_expand_px;

flat out ivec3 v_cell;  // cell i, j and triangle (0 = tri1, 1 = tri2)
flat out vec3 v_corner_z;  // source Z of the three corners, for exact depth per fragment

vec3 corner_point(ivec2 c) {
    float z = vertex_depth(c);
    vec2 uv = vec2(vertex_pos(c.x, u_src_size.x), vertex_pos(c.y, u_src_size.y));
    vec3 p_src = vec3((uv - u_src_k.zw) * z / u_src_k.xy, z);
    return (u_target_from_source * vec4(p_src, 1.0)).xyz;
}

vec2 window_xy(vec4 clip) {
    return (clip.xy / clip.w * 0.5 + 0.5) * u_dst_size;
}

void main() {
    int t = gl_VertexID / 3;
    int k = gl_VertexID - 3 * t;
    uint code = texelFetch(u_tris, ivec2(t % TRI_TEX_WIDTH, t / TRI_TEX_WIDTH), 0).r;
    int cell = int(code >> 1u);
    int tri = int(code & 1u);
    int cells_x = u_src_size.x + 1;
    ivec2 c = ivec2(cell % cells_x, cell / cells_x);
    ivec2 corners[3] = ivec2[3](c, tri == 0 ? c + ivec2(1, 0) : c + ivec2(1, 1),
                                   tri == 0 ? c + ivec2(1, 1) : c + ivec2(0, 1));
    vec3 p[3];
    vec4 clip[3];
    for (int n = 0; n < 3; ++n) {
        p[n] = corner_point(corners[n]);
        clip[n] = u_clip_from_target * vec4(p[n], 1.0);
    }
    v_cell = ivec3(c, tri);
    vec3 point = p[k];

    if (u_expand_px > 0.0 && clip[0].w > 0.0 && clip[1].w > 0.0 && clip[2].w > 0.0) {
        vec2 w0 = window_xy(clip[k]);
        vec2 wn = window_xy(clip[(k + 1) % 3]);
        vec2 wp = window_xy(clip[(k + 2) % 3]);
        vec2 e1 = wn - w0;
        vec2 e2 = w0 - wp;
        float area2 = e1.x * (wp.y - w0.y) - e1.y * (wp.x - w0.x);
        float l1 = length(e1);
        float l2 = length(e2);
        if (abs(area2) > 1e-12 && l1 > 0.0 && l2 > 0.0) {
            float s = sign(area2);
            vec2 n1 = s * vec2(e1.y, -e1.x) / l1;
            vec2 n2 = s * vec2(e2.y, -e2.x) / l2;
            // Miter offset moving both adjacent edges out by u_expand_px; capped at sharp corners.
            float denom = max(1.0 + dot(n1, n2), 0.25);
            vec2 w_new = w0 + u_expand_px * (n1 + n2) / denom;
            // Ray through the moved window point, met with the triangle's plane, so the moved
            // vertex stays on the surface and interpolation stays exact.
            vec2 ndc = w_new / u_dst_size * 2.0 - 1.0;
            mat4 m = u_clip_from_target;
            vec3 dir = vec3((ndc.x - m[2][0]) / m[0][0], (ndc.y - m[2][1]) / m[1][1], 1.0);
            vec3 nrm = cross(p[1] - p[0], p[2] - p[0]);
            float den = dot(nrm, dir);
            float zmin = min(p[0].z, min(p[1].z, p[2].z));
            float zmax = max(p[0].z, max(p[1].z, p[2].z));
            if (abs(den) > 1e-30) {
                vec3 moved = dir * (dot(nrm, p[0]) / den);
                if (moved.z >= 0.5 * zmin && moved.z <= 2.0 * zmax) {
                    point = moved;
                }
            }
        }
    }
    v_corner_z = vec3(vertex_depth(corners[0]), vertex_depth(corners[1]), vertex_depth(corners[2]));
    gl_Position = u_clip_from_target * vec4(point, 1.0);
}
