// The rasteriser only proposes (pixel, triangle) pairs: the pixel centre's exact source point
// (from the f64 per-column/row lookups, as in the full-screen pass) is tested against the
// fragment's own closed triangle and valued there. Interpolated attributes would carry the
// rasteriser's 1/256 px vertex snapping, and interpolated UVs (seed 003) are not even exact in
// exact arithmetic for a focal change.

flat in ivec3 v_cell;

layout(location = 0) out vec4 o_rgb;
layout(location = 1) out float o_depth;
layout(location = 2) out float o_mask;

// Local coordinate in cell `own` of a point given as (cell, local) by the lookup.
float own_local(float lookup_cell, float lookup_local, int own, int n) {
    int lc = int(lookup_cell);
    float x0 = vertex_pos(lc, n);
    float w = vertex_pos(lc + 1, n) - x0;
    float own_x0 = vertex_pos(own, n);
    return ((x0 - own_x0) + lookup_local * w) / (vertex_pos(own + 1, n) - own_x0);
}

void main() {
    vec4 cx, cy;
    pixel_lookups(cx, cy);
    ivec2 c = v_cell.xy;
    vec2 ab = vec2(own_local(cx.x, cx.y, c.x, u_src_size.x), own_local(cy.x, cy.y, c.y, u_src_size.y));
    if (cx.x < 0.0 || cy.x < 0.0 || !inside_tri(ab, v_cell.z)) {
        discard;
    }
    vec4 zc = cell_depths(c);
    vec3 z = v_cell.z == 0 ? zc.xyw : zc.xwz;
#if WANT_RGB
    // The cell spans source pixels c - 1 .. c (clamped at the border ring): the bilinear footprint.
    o_rgb = vec4(cell_rgb(c, clamp(ab, 0.0, 1.0)), 1.0);
#else
    o_rgb = vec4(0.0);
#endif
    o_depth = tri_depth(ab, v_cell.z, z);
    o_mask = MASK_SET;
}
