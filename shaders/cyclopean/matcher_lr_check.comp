// Left-right consistency (the twin's `left_right_check`): an eye's disparity is kept where the
// other eye's, read at the pixel it points to (round_half_away, matcher_params.glsl),
// is known and within LR_TOLERANCE_PX; 0 elsewhere. The sums and differences are single f32
// operations, correctly rounded in GLSL as on the CPU, so the decisions are the twin's.
layout(std430, STORAGE_BUFFER(0)) readonly buffer Raw {
    float raw[];  // left eye, then right eye
};
layout(std430, STORAGE_BUFFER(1)) writeonly buffer Checked {
    float checked[];
};

// Eye `own` (0 left, 1 right) at pixel p: its disparity points to x + sign d in the other eye.
float checked_disparity(int own, ivec2 p, float sign) {
    int row = p.y * u_size.x;
    float d = raw[own * pixels() + row + p.x];
    if (d <= 0.0) {
        return 0.0;
    }
    precise float at = float(p.x) + sign * d;
    float xo = round_half_away(at);
    if (xo < 0.0 || xo >= float(u_size.x)) {
        return 0.0;
    }
    float e = raw[(1 - own) * pixels() + row + int(xo)];
    precise float gap = abs(d - e);
    return (e > 0.0 && gap <= LR_TOLERANCE_PX) ? d : 0.0;
}

void main() {
    ivec2 p = this_pixel();
    if (p.x < 0) {
        return;
    }
    int i = p.y * u_size.x + p.x;
    checked[i] = checked_disparity(0, p, -1.0);
    checked[pixels() + i] = checked_disparity(1, p, 1.0);
}
