// The mesh path's first draw under --rgb-everywhere: the bilinear source colour at every target
// pixel inside the source frame (same pose: where a source pixel lands does not depend on its
// depth), depth and mask left invalid. It writes the far depth, so the mesh draws after it pass
// the depth test and overwrite every pixel a kept triangle covers with their colour, depth and
// mask (the same bilinear colour: cell_rgb of the same point).

layout(location = 0) out vec4 o_rgb;
layout(location = 1) out float o_depth;
layout(location = 2) out float o_mask;

void main() {
    vec4 cx, cy;
    pixel_lookups(cx, cy);
    // The cleared far value: window depth 1, or 0 under reversed-Z (depth clamp keeps it in range).
#if REVERSED_Z
    gl_FragDepth = 0.0;
#else
    gl_FragDepth = 1.0;
#endif
    o_depth = 0.0;
    o_mask = 0.0;
    if (cx.x < 0.0 || cy.x < 0.0) {
        o_rgb = vec4(0.0);
        return;
    }
    o_rgb = vec4(cell_rgb(ivec2(cx.x, cy.x), clamp(vec2(cx.y, cy.y), 0.0, 1.0)), 1.0);
}
