// Splat pass of the splat-gather method (src/cyclopean/splat.rs; f64 twin: splat_reference.rs).
// Into an image the driver cleared to "no surface" (0xFFFFFFFF, Framebuffer::clear): each valid
// eye texel's surface point to the middle pixel its one-pixel footprint covers (the floor of its
// window position), nearest first: positive floats order like their bit patterns, so an atomic
// min on the bits keeps the nearest middle distance.

layout(local_size_x = 8, local_size_y = 8) in;
// Parameters (`SplatParams` in src/cyclopean/splat.rs), one block for GL and Vulkan.
layout(std140, binding = 0) PARAM_BLOCK SplatParams {
    mat4 u_inv_view_e;
    mat4 u_ray_basis_e;
    mat4 u_view_proj_m;
    mat4 u_view_m;
    ivec2 u_grid;       // invocation grid: the eye's size
    ivec2 u_size_m;
};
layout(binding = 1) uniform sampler2D u_dist;   // R32F eye view distance, memory order (0 = invalid)
layout(r32ui, STORAGE_IMAGE(0)) uniform uimage2D u_splat;

void main() {
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(t, u_grid))) {
        return;
    }
    float z = texelFetch(u_dist, t, 0).r;
    if (!(z > 0.0) || isinf(z)) {
        return;
    }
    vec3 ray = view_ray(u_ray_basis_e, ndc_of_pixel(vec2(t), vec2(u_grid)));
    vec4 world = vec4(transform_point(u_inv_view_e, ray * z), 1.0);
    vec4 clip = u_view_proj_m * world;
    if (!(clip.w > 0.0)) {
        return;
    }
    vec2 px = floor(window_of_clip(clip, vec2(u_size_m)));
    float zm = -(u_view_m * world).z;
    if (any(lessThan(px, vec2(0.0))) || any(greaterThanEqual(px, vec2(u_size_m))) || !(zm > 0.0) || isinf(zm)) {
        return;
    }
    imageAtomicMin(u_splat, ivec2(px), floatBitsToUint(zm));
}
