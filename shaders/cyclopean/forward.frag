// Colour of the warped eye at the exact eye position of this fragment's surface point.

// Parameters and images: shaders/cyclopean/forward_params.glsl (one block, both backends).

const float FORWARD_CELL_EPS = 1e-3;

flat in ivec3 v_cell;
in vec3 v_eye_clip;
in float v_middle_distance;

layout(location = 0) out vec4 o_color;
layout(location = 1) out float o_depth;
layout(location = 2) out float o_sources;

void main() {
    ivec2 size = textureSize(u_color, 0);
    vec2 uv = v_eye_clip.xy / v_eye_clip.z * 0.5 + 0.5;
    // Closed-triangle test in the eye's grid (image rows, refocus cell convention).
    vec2 img = uv * vec2(size) - 0.5;
#if !ROWS_TOP_DOWN
    img.y = float(size.y) - 1.0 - img.y;
#endif
    ivec2 c = v_cell.xy;
    vec2 origin = vec2(vertex_pos(c.x, size.x), vertex_pos(c.y, size.y));
    vec2 end = vec2(vertex_pos(c.x + 1, size.x), vertex_pos(c.y + 1, size.y));
    vec2 ab = (img - origin) / (end - origin);
    // Looser than the refocus passes' 1e-5 (their local point comes from f64 lookups): here it
    // comes from the rasteriser's interpolation of the eye clip position, in f32.
    if (!inside_closed_triangle(ab, v_cell.z, FORWARD_CELL_EPS)) {
        discard;
    }
    vec2 t = uv * vec2(size) - 0.5;
    vec2 f0 = floor(t);
    vec2 fr = t - f0;
    ivec2 i0 = ivec2(f0);
    ivec2 hi = size - 1;
    vec3 c00 = texelFetch(u_color, clamp(i0, ivec2(0), hi), 0).rgb;
    vec3 c10 = texelFetch(u_color, clamp(i0 + ivec2(1, 0), ivec2(0), hi), 0).rgb;
    vec3 c01 = texelFetch(u_color, clamp(i0 + ivec2(0, 1), ivec2(0), hi), 0).rgb;
    vec3 c11 = texelFetch(u_color, clamp(i0 + ivec2(1, 1), ivec2(0), hi), 0).rgb;
    o_color = vec4(bilinear(c00, c10, c01, c11, fr), 1.0);
    o_depth = v_middle_distance;
    o_sources = float(u_eye_bit) / 255.0;
}
