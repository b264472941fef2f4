// Same-pose refocus without a mesh: each target pixel finds the grid cell its ray meets in the
// source image and evaluates the same kept triangles analytically (1/Z is affine over a
// triangle in the source image), giving the mesh path's output in one full-screen pass.

// R8UI per cell, (W+1) x (H+1): 1 tri1 kept, 2 tri2 kept, 4 left edge, 8 top edge, 16 top-left
// vertex covered by some kept triangle (grid.rs coverage_flags).
layout(binding = 5) uniform usampler2D u_keep;

layout(location = 0) out vec4 o_rgb;
layout(location = 1) out float o_depth;
layout(location = 2) out float o_mask;

// Z of the kept surface at local point ab of cell c, or NONE. Inside a kept triangle: exact.
// On the cell's left/top border (a point there is always given to the right/lower cell), the
// edge and vertex flags say whether any kept triangle, this cell's or a neighbour's, holds it;
// its Z then interpolates 1/Z along that edge. One cell per pixel: llvmpipe runs every branch
// under a mask, so testing neighbour cells would cost their fetches on every pixel.
const float NONE = 3.0e38;

float surface_depth(ivec2 c, vec2 ab, bvec2 border) {
    uint bits = texelFetch(u_keep, c, 0).r;
    vec4 zc = cell_depths(c);
    float z00 = zc.x, z10 = zc.y, z01 = zc.z, z11 = zc.w;
    bool in1 = (bits & 1u) != 0u && inside_tri(ab, 0);
    bool in2 = (bits & 2u) != 0u && inside_tri(ab, 1);
    if (in1 || in2) {
        return in1 ? tri_depth(ab, 0, vec3(z00, z10, z11)) : tri_depth(ab, 1, vec3(z00, z11, z01));
    }
    if (border.x && border.y) {
        return (bits & 16u) != 0u ? z00 : NONE;
    }
    if (border.x) {
        return (bits & 4u) != 0u ? 1.0 / mix(1.0 / z00, 1.0 / z01, clamp(ab.y, 0.0, 1.0)) : NONE;
    }
    if (border.y) {
        return (bits & 8u) != 0u ? 1.0 / mix(1.0 / z00, 1.0 / z10, clamp(ab.x, 0.0, 1.0)) : NONE;
    }
    return NONE;
}

void main() {
    vec4 cx, cy;
    pixel_lookups(cx, cy);

    o_rgb = vec4(0.0);
    o_depth = 0.0;
    o_mask = 0.0;
    if (cx.x < 0.0 || cy.x < 0.0) {
        return;
    }
    ivec2 c0 = ivec2(cx.x, cy.x);
#if WANT_RGB && RGB_EVERYWHERE
    // Same pose: where a source pixel lands does not depend on its depth, so every pixel inside
    // the source frame gets its bilinear colour; depth and mask keep their meaning below.
    o_rgb = vec4(cell_rgb(c0, clamp(vec2(cx.y, cy.y), 0.0, 1.0)), 1.0);
#endif
    float z = surface_depth(c0, vec2(cx.y, cy.y), bvec2(cx.z != 0.0, cy.z != 0.0));
    if (z >= NONE) {
        return;
    }
#if WANT_RGB && !RGB_EVERYWHERE
    // Cell c spans source pixels c - 1 .. c (clamped at the border ring), exactly the bilinear
    // footprint of its points, with the local coordinate as weight.
    o_rgb = vec4(cell_rgb(c0, clamp(vec2(cx.y, cy.y), 0.0, 1.0)), 1.0);
#endif
    o_depth = z;
    o_mask = MASK_SET;
}
