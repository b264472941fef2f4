// Same-pose refocus without a mesh: each target pixel finds the grid cell its ray meets in the
// source image and evaluates the same kept triangles analytically (1/Z is affine over a
// triangle in the source image), giving the mesh path's output in one full-screen pass.

uniform usampler2D u_keep;  // R8UI per cell: bit 0 tri1 kept, bit 1 tri2 kept; (W+1) x (H+1)

layout(location = 0) out vec4 o_rgb;
layout(location = 1) out float o_depth;
layout(location = 2) out float o_mask;

// Nearest Z over the kept triangles of cell c containing uv; `best` if none is nearer.
float cell_depth(ivec2 c, dvec2 uv, float best) {
    uint bits = texelFetch(u_keep, c, 0).r;
    if (bits == 0u) {
        return best;
    }
    vec2 ab = cell_local(c, uv);
    float z00 = vertex_depth(c);
    float z11 = vertex_depth(c + ivec2(1, 1));
    if ((bits & 1u) != 0u && inside_tri(ab, 0)) {
        best = min(best, tri_depth(ab, 0, vec3(z00, vertex_depth(c + ivec2(1, 0)), z11)));
    }
    if ((bits & 2u) != 0u && inside_tri(ab, 1)) {
        best = min(best, tri_depth(ab, 1, vec3(z00, z11, vertex_depth(c + ivec2(0, 1)))));
    }
    return best;
}

void main() {
    dvec2 uv = same_pose_source_point();

    o_rgb = vec4(0.0);
    o_depth = 0.0;
    o_mask = 0.0;
    dvec2 lo = dvec2(-0.5 - 0.5 * CELL_EPS);
    dvec2 hi = dvec2(u_src_size) - 0.5 + 0.5 * CELL_EPS;
    if (any(lessThan(uv, lo)) || any(greaterThan(uv, hi))) {
        return;
    }
    ivec2 c0 = clamp(ivec2(floor(uv)) + 1, ivec2(0), u_src_size);
    vec2 ab = cell_local(c0, uv);
    // Neighbour cells matter only for points on (or within CELL_EPS of) a cell border.
    ivec2 step = ivec2(ab.x <= CELL_EPS ? -1 : (ab.x >= 1.0 - CELL_EPS ? 1 : 0),
                       ab.y <= CELL_EPS ? -1 : (ab.y >= 1.0 - CELL_EPS ? 1 : 0));
    ivec2 c1 = clamp(c0 + step, ivec2(0), u_src_size);
    const float NONE = 3.0e38;
    float z = cell_depth(c0, uv, NONE);
    if (c1.x != c0.x) {
        z = cell_depth(ivec2(c1.x, c0.y), uv, z);
    }
    if (c1.y != c0.y) {
        z = cell_depth(ivec2(c0.x, c1.y), uv, z);
        if (c1.x != c0.x) {
            z = cell_depth(c1, uv, z);
        }
    }
    if (z >= NONE) {
        return;
    }
#if WANT_RGB
    o_rgb = vec4(bilinear_rgb(uv), 1.0);
#endif
    o_depth = z;
    o_mask = 1.0;
}
