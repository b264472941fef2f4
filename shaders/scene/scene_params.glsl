// scene/raytrace's interface, the same text for GL and Vulkan: the std140 parameter block
// (binding 0) mirrored by `RaytraceParams` in src/scene/render.rs. No images.
const int MAX_OBJECTS = 32;
layout(std140, binding = 0) PARAM_BLOCK RaytraceParams {
    // Pixel NDC (x, y, 1, 0) -> ray direction (src/camera/rays.rs ray_basis): the same rays under
    // every convention.
    mat4 u_ray_basis;
    mat4 u_view_proj;
    mat4 u_view;
    vec3 u_eye;
    // Omni-directional stereo equirect camera instead of the GL camera (rows top-down,
    // longitude 0 = +z, +90 deg = +x, row 0 = up = -y): each pixel's ray starts on the circle
    // of radius u_ods_radius (signed: -left, +right) tangent to its direction, faded to 0
    // towards the poles from latitude u_ods_fade_start (same rule as src/stitch OdsRig).
    float u_ods_radius;
    vec3 u_ods_centre;
    float u_ods_fade_start;
    vec2 u_size;
    int u_count;
    int u_ods;
    ivec4 u_kind[MAX_OBJECTS];  // x: 0 plane, 1 sphere, 2 cuboid; y: pattern
    vec4 u_a[MAX_OBJECTS];      // plane point | sphere centre, radius | cuboid min
    vec4 u_b[MAX_OBJECTS];      // plane normal | - | cuboid max
    vec4 u_c[MAX_OBJECTS];      // plane bounds min
    vec4 u_d[MAX_OBJECTS];      // plane bounds max
};
