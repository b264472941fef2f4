// The pixels of the middle view a depth edge may cross, appended by the splat-gather draw and
// mixed by splat_edges.comp (src/cyclopean/splat.rs), one invocation each. The first word is
// the append counter; the next three are the edge pass's indirect dispatch (work groups of
// EDGE_GROUP_SIZE: one more each time the counter passes a multiple of it, up to
// EDGE_MAX_GROUPS, the least GL_MAX_COMPUTE_WORK_GROUP_COUNT any GL 4.3 driver allows, beyond
// which each invocation takes more than one pixel; 1; 1). Each pixel is packed as y << 16 | x.
#define EDGE_GROUP_SIZE_INT 64
const uint EDGE_GROUP_SIZE = uint(EDGE_GROUP_SIZE_INT);
const uint EDGE_MAX_GROUPS = 65535u;

layout(std430, STORAGE_BUFFER(0)) buffer EdgeList {
    uint edge_count;
    uint edge_groups;
    uint edge_groups_y;
    uint edge_groups_z;
    uint edge_pixel[];
};
