// A fragment of an interior triangle: the pixel centre lies within the rasteriser's snapping
// (1/512 px) of that triangle, so in a triangle sharing one of its surrounded corners, which is
// kept. Its exact cell comes from the f64 lookups and the triangle from the diagonal; no test
// is needed and the fill rule cannot drop a pixel here.

layout(location = 0) out vec4 o_rgb;
layout(location = 1) out float o_depth;
layout(location = 2) out float o_mask;

void main() {
    vec4 cx, cy;
    pixel_lookups(cx, cy);
    ivec2 c = ivec2(cx.x, cy.x);
    vec2 ab = clamp(vec2(cx.y, cy.y), 0.0, 1.0);
    int tri = ab.x >= ab.y ? 0 : 1;
    vec4 zc = cell_depths(c);
    vec3 z = tri == 0 ? zc.xyw : zc.xwz;
#if WANT_RGB
    o_rgb = vec4(cell_rgb(c, ab), 1.0);
#else
    o_rgb = vec4(0.0);
#endif
    o_depth = tri_depth(ab, tri, z);
    o_mask = MASK_SET;
}
