// Each eye's confidence in its final disparity (src/cyclopean/matcher/confidence.rs holds the
// rule and the twin): 0 where unknown, where it points outside the other image or to an unknown
// or 1 px or more different disparity there; else the agreement 1 - |d - e| / LR_TOLERANCE_PX
// over 1 + the variance of the known disparities of the 3 x 3 neighbourhood.
layout(std430, STORAGE_BUFFER(0)) readonly buffer Final {
    float final_disparity[];  // left eye, then right eye
};
layout(r32f, STORAGE_IMAGE(0)) writeonly uniform image2D u_left_confidence;
layout(r32f, STORAGE_IMAGE(1)) writeonly uniform image2D u_right_confidence;

float confidence(int own, ivec2 p, float sign) {
    int base = own * pixels();
    float d = final_disparity[base + p.y * u_size.x + p.x];
    if (d <= 0.0) {
        return 0.0;
    }
    precise float at = float(p.x) + sign * d;
    float xo = round_half_away(at);
    if (xo < 0.0 || xo >= float(u_size.x)) {
        return 0.0;
    }
    float e = final_disparity[(1 - own) * pixels() + p.y * u_size.x + int(xo)];
    precise float gap = abs(d - e);
    if (e <= 0.0 || gap >= LR_TOLERANCE_PX) {
        return 0.0;
    }
    float sum = 0.0;
    float known = 0.0;
    for (int y = max(p.y - 1, 0); y <= min(p.y + 1, u_size.y - 1); ++y) {
        for (int x = max(p.x - 1, 0); x <= min(p.x + 1, u_size.x - 1); ++x) {
            float v = final_disparity[base + y * u_size.x + x];
            if (v > 0.0) {
                sum += v;
                known += 1.0;
            }
        }
    }
    float mean = sum / known;
    float spread = 0.0;
    for (int y = max(p.y - 1, 0); y <= min(p.y + 1, u_size.y - 1); ++y) {
        for (int x = max(p.x - 1, 0); x <= min(p.x + 1, u_size.x - 1); ++x) {
            float v = final_disparity[base + y * u_size.x + x];
            if (v > 0.0) {
                spread += (v - mean) * (v - mean);
            }
        }
    }
    return (1.0 - gap / LR_TOLERANCE_PX) / (1.0 + spread / known);
}

void main() {
    ivec2 p = this_pixel();
    if (p.x < 0) {
        return;
    }
    imageStore(u_left_confidence, p, vec4(confidence(0, p, -1.0), 0.0, 0.0, 0.0));
    imageStore(u_right_confidence, p, vec4(confidence(1, p, 1.0), 0.0, 0.0, 0.0));
}
