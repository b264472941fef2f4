// Seed 002's texture-space shift as a gather (rules in src/reproject/mod.rs). The f64 twin is
// src/reproject/reference.rs: keep them in step. Pixel units: source column s at inverse depth q
// lands at s + a - b q on the same row.
// Defines: DEPTH_MODE (0 view Z, 1 device depth, 2 disparity), SCAN (exact scan, else walk),
// SCAN_MARGIN, plus the conventions preamble (REVERSED_Z, through common/depth.glsl).

// Parameters and images: shaders/reproject/reproject_params.glsl (one block, both backends).

layout(location = 0) out vec4 o_color;
layout(location = 1) out float o_depth;
layout(location = 2) out float o_mask;

int g_width;
int g_row;

// Inverse depth of texel j of this row, or -1 where invalid.
float inv_depth(int j) {
    float d = texelFetch(u_depth, ivec2(j, g_row), 0).r;
    if (isnan(d) || isinf(d)) {
        return -1.0;
    }
#if DEPTH_MODE == 0
    float q = 1.0 / d;
#elif DEPTH_MODE == 1
    if (device_depth_is_background(d)) return -1.0;
    float q = u_alpha * d + u_beta;
#else
    if (d <= 0.0) return -1.0;
    float q = u_alpha * d + u_beta;
#endif
    return (q > 0.0 && !isinf(q)) ? q : -1.0;
}

struct Hit {
    bool ok;
    float q;
    vec3 color;
    bool hole;  // depth-edge segment: an unseen surface, hides what lies behind it
};

// Segment [j, j+1] covering target column u, or a miss.
Hit segment(int j, float u) {
    Hit miss = Hit(false, 0.0, vec3(0.0), false);
    if (j < 0 || j + 1 >= g_width) {
        return miss;
    }
    float q0 = inv_depth(j);
    float q1 = inv_depth(j + 1);
    if (q0 < 0.0 || q1 < 0.0) {
        return miss;
    }
    float f0 = float(j) + u_a - u_b * q0;
    float f1 = float(j + 1) + u_a - u_b * q1;
    bool hole = abs(q0 - q1) > u_tau_rel * min(q0, q1) || f1 <= f0;
    // A hole also covers the gap mapped at either end's depth: one pixel beyond each end.
    float pad = hole ? 1.0 : 0.0;
    if (!(min(f0, f1 - pad) <= u && u <= max(f0 + pad, f1))) {
        return miss;
    }
    float t = f1 != f0 ? clamp((u - f0) / (f1 - f0), 0.0, 1.0) : 0.0;
    vec3 c0 = texelFetch(u_color, ivec2(j, g_row), 0).rgb * 255.0;
    vec3 c1 = texelFetch(u_color, ivec2(j + 1, g_row), 0).rgb * 255.0;
    return Hit(true, q0 + (q1 - q0) * t, c0 + (c1 - c0) * t, hole);
}

// Nearer of two; ties keep the first unless only it is a hole.
Hit nearer(Hit best, Hit h) {
    return (h.ok && (!best.ok || h.q > best.q || (h.q == best.q && best.hole && !h.hole))) ? h : best;
}

#if !SCAN
Hit walk(float u, float s) {
    for (int k = 0; k < u_steps; ++k) {
        int j = clamp(int(floor(s + 0.5)), 0, g_width - 1);
        float q = inv_depth(j);
        if (q < 0.0) {
            break;
        }
        s = u - u_a + u_b * q;
    }
    int j0 = clamp(int(floor(s)), -1, g_width);
    Hit best = Hit(false, 0.0, vec3(0.0), false);
    for (int j = j0 - 1; j <= j0 + 1; ++j) {
        best = nearer(best, segment(j, u));
    }
    return best;
}
#endif

void main() {
    g_width = textureSize(u_depth, 0).x;
    g_row = int(gl_FragCoord.y);
    float u = gl_FragCoord.x - 0.5;
    Hit best = Hit(false, 0.0, vec3(0.0), false);
    if (u_q_max > 0.0) {
#if SCAN
        float s_a = u - u_a + u_b * u_q_min;
        float s_b = u - u_a + u_b * u_q_max;
        int lo = max(int(floor(min(s_a, s_b))) - 1 - SCAN_MARGIN, 0);
        int hi = min(int(floor(max(s_a, s_b))) + SCAN_MARGIN, g_width - 2);
        for (int j = lo; j <= hi; ++j) {
            best = nearer(best, segment(j, u));
        }
#else
        best = walk(u, u);
        best = nearer(best, walk(u, u - u_a + u_b * u_q_max));
#endif
    }
    if (best.ok && !best.hole) {
        o_color = vec4(best.color / 255.0, 1.0);
        o_depth = 1.0 / best.q;
        o_mask = 1.0;
    } else {
        o_color = vec4(0.0, 0.0, 0.0, 1.0);
        o_depth = 0.0;
        o_mask = 0.0;
    }
}
