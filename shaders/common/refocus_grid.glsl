// The refocus grid (see src/refocus/grid.rs and common/grid_mesh.glsl): vertex column i
// carries the depth of source pixel clamp(i - 1, 0, W - 1).


// Closed-triangle tolerance in cell units (grid.rs CELL_EPS): pixel centres exactly on an edge
// are covered by both neighbours whatever the rasteriser's fill rule or the row order. Local
// coordinates come from doubles, so f32 rounding (~6e-8) is all it has to absorb.
const float CELL_EPS = 1e-5;

float vertex_depth(ivec2 c) {
    return texelFetch(u_src_depth, clamp(c - 1, ivec2(0), u_src_size - 1), 0).r;
}

