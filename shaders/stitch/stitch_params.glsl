// stitch/stitch's interface, the same text for GL and Vulkan: the std140 parameter block
// (binding 0) mirrored by `StitchParamsBlock` in src/stitch/render.rs, one per eye's draw, and
// the eye's face atlases (bindings 1, 2).
layout(std140, binding = 0) PARAM_BLOCK StitchParams {
    mat4 u_rot[6];      // world from face rotation (upper 3x3)
    vec4 u_eye[6];      // face eyes (xyz)
    vec4 u_centre;      // ODS circle centre (xyz)
    ivec2 u_size;       // equirect size per eye
    float u_f;
    float u_c;
    int u_n;
    float u_half_ipd;
    float u_fade_start; // radians
    float u_side;       // -1 left, +1 right
    float u_overlap;    // radians
    int u_row0;         // first framebuffer row of this eye
};
layout(binding = 1) uniform sampler2D u_color;  // RGBA8 atlas: face k at columns [k n, (k + 1) n), rows in memory order
layout(binding = 2) uniform sampler2D u_depth;  // R32F atlas, view Z, <= 0 / NaN / Inf = background
