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
    vec3 z = tri == 0 ? vec3(vertex_depth(c), vertex_depth(c + ivec2(1, 0)), vertex_depth(c + ivec2(1, 1)))
                      : vec3(vertex_depth(c), vertex_depth(c + ivec2(1, 1)), vertex_depth(c + ivec2(0, 1)));
#if WANT_RGB
    o_rgb = vec4(bilinear_rgb_at(c - 1, ab), 1.0);
#else
    o_rgb = vec4(0.0);
#endif
    o_depth = tri_depth(ab, tri, z);
    o_mask = 1.0;
}
