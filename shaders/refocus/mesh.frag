// Colour is sampled where the fragment's surface point projects into the source image (exact
// for any pose, unlike interpolated UVs); depth is the interpolated view-space Z.

flat in ivec3 v_cell;
in vec3 v_src_h;
in float v_depth;

layout(location = 0) out vec4 o_rgb;
layout(location = 1) out float o_depth;
layout(location = 2) out float o_mask;

void main() {
    ivec2 c = v_cell.xy;
    vec2 origin = vec2(vertex_pos(c.x, u_src_size.x), vertex_pos(c.y, u_src_size.y));
    vec2 cell_size = vec2(vertex_pos(c.x + 1, u_src_size.x), vertex_pos(c.y + 1, u_src_size.y)) - origin;
    vec2 local = v_src_h.xy / v_src_h.z;
    if (!inside_tri(local / cell_size, v_cell.z)) {
        discard;
    }
#if WANT_RGB
    o_rgb = vec4(bilinear_rgb(origin + local), 1.0);
#else
    o_rgb = vec4(0.0);
#endif
    o_depth = v_depth;
    o_mask = 1.0;
}
