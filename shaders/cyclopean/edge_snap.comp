// Edge snap of one eye's distances, once per frame before the splat-gather passes
// (src/cyclopean/splat.rs; f64 twin: src/cyclopean/edge_snap.rs, keep them in step).
// A depth break between texels a | b (both known, full-baseline disparities more than the
// tolerance apart) may sit one texel off the colour edge. The texel beside the break joins the
// side across it when its colour is nearer the texel across (by more than the margin, L1 over
// RGB in 8-bit levels) than its own side's next texel, and the texel across does not claim the
// move the other way more strongly; it then takes that side's disparity continued one texel.
// A texel with a break on both sides (a surface one texel wide) never moves. Colours are
// compared as integers so that the decision is exact on every GPU and in the twin.

layout(local_size_x = 8, local_size_y = 8) in;
// Parameters (`EdgeSnapParams` in src/cyclopean/splat.rs), one block for GL and Vulkan.
layout(std140, binding = 0) PARAM_BLOCK EdgeSnapParams {
    float u_parallax_px;  // full-baseline disparity = this / distance
    float u_tolerance_px;
    int u_margin;
};
layout(binding = 1) uniform sampler2D u_dist;   // R32F eye view distance, memory order (0 = invalid)
layout(binding = 2) uniform sampler2D u_color;  // RGBA8, memory order
layout(r32f, STORAGE_IMAGE(0)) uniform writeonly image2D u_snapped;

float disparity(ivec2 t) {
    float z = texelFetch(u_dist, t, 0).r;
    return (z > 0.0 && !isinf(z)) ? u_parallax_px / z : 0.0;
}

ivec3 rgb(ivec2 t) {
    return ivec3(round(texelFetch(u_color, t, 0).rgb * 255.0));
}

int l1(ivec3 a, ivec3 b) {
    ivec3 d = abs(a - b);
    return d.x + d.y + d.z;
}

bool joined(float a, float b) {
    return a > 0.0 && b > 0.0 && abs(a - b) <= u_tolerance_px;
}

bool broken(float a, float b) {
    return a > 0.0 && b > 0.0 && abs(a - b) > u_tolerance_px;
}

// The side's disparity continued one texel outward from its edge texel d1 (d2: the next inward).
float extend(float d1, float d2) {
    return joined(d1, d2) ? 2.0 * d1 - d2 : d1;
}

void main() {
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = textureSize(u_dist, 0);
    if (any(greaterThanEqual(t, size))) {
        return;
    }
    float z = texelFetch(u_dist, t, 0).r;
    float snapped = z;
    if (t.x >= 2 && t.x < size.x - 2 && z > 0.0 && !isinf(z)) {
        float d[5];
        ivec3 c[5];
        for (int k = 0; k < 5; ++k) {
            ivec2 q = ivec2(t.x - 2 + k, t.y);
            d[k] = disparity(q);
            c[k] = rgb(q);
        }
        float moved = 0.0;
        if (broken(d[1], d[2]) && joined(d[2], d[3])) {
            // Break on the left: this texel (b) against the texel across (a = k 1).
            int own = l1(c[2], c[3]) - l1(c[2], c[1]);
            int other = l1(c[1], c[0]) - l1(c[1], c[2]);
            if (own > u_margin && own >= other) {
                moved = extend(d[1], d[0]);
            }
        } else if (broken(d[2], d[3]) && joined(d[2], d[1])) {
            // Break on the right: this texel (a) against the texel across (b = k 3).
            int own = l1(c[2], c[1]) - l1(c[2], c[3]);
            int other = l1(c[3], c[4]) - l1(c[3], c[2]);
            if (own > u_margin && own > other) {
                moved = extend(d[3], d[4]);
            }
        }
        if (moved > 0.0) {
            snapped = u_parallax_px / moved;
        }
    }
    imageStore(u_snapped, t, vec4(snapped, 0.0, 0.0, 0.0));
}
