// Matched or inferred (src/stereo/trust.rs holds the rule, trust_reference.rs its twin): each
// eye's semi-global disparity is kept where the census matcher, run earlier in the same run on
// the same pair, found the same within AGREE_PX, or found none and the census window is flat
// (grey range within FLAT_GREY: no texture to disagree with); any other is inferred from the
// surface around it and written 0. Integer grey levels (the matcher's own, both eyes a word) and
// one f32 subtraction: the GPU decides as the twin does, bit for bit.
// u_pairs: 1 when the census disparities were matched in this run; 0 when the search passed
// CENSUS_CHECK_SEARCH and none is known (only flat windows count then).
layout(std430, STORAGE_BUFFER(0)) readonly buffer SemiGlobal {
    float semi_global[];  // final disparities, left eye, then right eye
};
layout(std430, STORAGE_BUFFER(1)) readonly buffer Census {
    float census[];  // the census matcher's final disparities, same layout
};
layout(std430, STORAGE_BUFFER(2)) readonly buffer Greys {
    uint greys[];  // r + g + b, left in the low half
};
layout(r32f, STORAGE_IMAGE(0)) writeonly uniform image2D u_left_matched;
layout(r32f, STORAGE_IMAGE(1)) writeonly uniform image2D u_right_matched;

// Largest difference (px) at which the two matchers agree.
const float AGREE_PX = 1.0;
// Largest grey range (r + g + b levels) of a flat census window.
const int FLAT_GREY = 20;

int grey(int eye, ivec2 q) {
    q = clamp(q, ivec2(0), u_size - 1);
    uint g = greys[q.y * u_size.x + q.x];
    return int(eye == 0 ? (g & 0xffffu) : (g >> 16));
}

float matched(int eye, ivec2 p) {
    int i = eye * pixels() + p.y * u_size.x + p.x;
    float s = semi_global[i];
    if (s <= 0.0) {
        return 0.0;
    }
    float c = u_pairs != 0 ? census[i] : 0.0;
    if (c > 0.0) {
        precise float gap = abs(s - c);
        return gap <= AGREE_PX ? s : 0.0;
    }
    int lo = 765;
    int hi = 0;
    for (int dy = -CENSUS_HALF_H; dy <= CENSUS_HALF_H; ++dy) {
        for (int dx = -CENSUS_HALF_W; dx <= CENSUS_HALF_W; ++dx) {
            int g = grey(eye, p + ivec2(dx, dy));
            lo = min(lo, g);
            hi = max(hi, g);
        }
    }
    return hi - lo <= FLAT_GREY ? s : 0.0;
}

void main() {
    ivec2 p = this_pixel();
    if (p.x < 0) {
        return;
    }
    imageStore(u_left_matched, p, vec4(matched(0, p), 0.0, 0.0, 0.0));
    imageStore(u_right_matched, p, vec4(matched(1, p), 0.0, 0.0, 0.0));
}
