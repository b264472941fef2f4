// Matching costs of one chunk of disparities: the Hamming distance of the left pixel's census
// code and the right pixel's d to its left, two disparities a word (16-bit lanes: sums of up to
// 81 costs of at most 34 never carry into the next lane). 0 where the disparity cannot exist
// (x < d, or d past the search range), so the box sums below skip those pixels as the twin's
// box clipped to x >= d does.
layout(std430, STORAGE_BUFFER(0)) readonly buffer Codes {
    uint codes[];
};
layout(std430, STORAGE_BUFFER(1)) writeonly buffer Costs {
    uint costs[];  // [pair][pixel]
};

uint hamming(int left, int right) {
    return uint(bitCount(codes[4 * left] ^ codes[4 * right + 2]) + bitCount(codes[4 * left + 1] ^ codes[4 * right + 3]));
}

void main() {
    ivec2 p = this_pixel();
    if (p.x < 0) {
        return;
    }
    int i = p.y * u_size.x + p.x;
    for (int k = 0; k < u_pairs; ++k) {
        uint word = 0u;
        for (int lane = 0; lane < 2; ++lane) {
            int d = u_first_d + 2 * k + lane;
            if (d <= u_max_disparity && p.x >= d) {
                word |= hamming(i, i - d) << (16 * lane);
            }
        }
        costs[k * pixels() + i] = word;
    }
}
