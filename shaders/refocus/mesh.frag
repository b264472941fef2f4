// The rasteriser only finds candidate (pixel, triangle) pairs: colour and depth come from the
// exact source point of the pixel centre evaluated on the fragment's own triangle, so they match
// the full-screen path and the f64 reference (interpolated UVs would not: seed 003's approach
// loses ~20 dB there).

uniform mat4 u_target_from_source;

flat in ivec3 v_cell;
flat in vec3 v_corner_z;

layout(location = 0) out vec4 o_rgb;
layout(location = 1) out float o_depth;
layout(location = 2) out float o_mask;

void main() {
    // The rasteriser's interpolation is only as exact as its vertex snapping (1/256 px), so the
    // source point is recomputed from the pixel centre; this refocus is same-pose.
    dvec2 uv = same_pose_source_point();
    vec2 ab = cell_local(v_cell.xy, uv);
    if (!inside_tri(ab, v_cell.z)) {
        discard;
    }
    float z_src = tri_depth(ab, v_cell.z, v_corner_z);
    vec3 p_src = vec3(vec2(uv - dvec2(u_src_k.zw)) / u_src_k.xy * z_src, z_src);
    // Target view-space Z: row 2 of the view transform (z_src itself for a same-pose refocus).
    vec4 row_z = vec4(u_target_from_source[0][2], u_target_from_source[1][2],
                      u_target_from_source[2][2], u_target_from_source[3][2]);
#if WANT_RGB
    o_rgb = vec4(bilinear_rgb(uv), 1.0);
#else
    o_rgb = vec4(0.0);
#endif
    o_depth = dot(row_z, vec4(p_src, 1.0));
    o_mask = 1.0;
}
