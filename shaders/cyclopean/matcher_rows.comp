// Costs and the box's horizontal sums of one chunk of disparities. One invocation per (row,
// disparity pair) slides the 9-column window along the row: each cost (the Hamming distance of
// the left pixel's census code and the right pixel's d to its left) is computed once, added
// as it enters and taken off as it leaves, two disparities a word in 16-bit lanes (sums of up
// to 81 costs of at most 34 never carry into, or borrow from, the next lane). A cost is 0
// where the disparity cannot exist (x < d, or d past the range), so the sums are the twin's
// over the box clipped to the image and to x >= d. Sliding, not summing 9 loads per pixel:
// on a CPU driver (llvmpipe) the loads are the cost.
layout(std430, STORAGE_BUFFER(0)) readonly buffer Codes {
    uint codes[];  // per pixel: left low, left high, right low, right high
};
layout(std430, STORAGE_BUFFER(1)) writeonly buffer Rows {
    uint rows[];  // [pair][pixel]
};

const int BOX = 2 * BOX_RADIUS + 1;

// Both lanes' costs at pixel i of a row, column x.
uint cost_word(int i, int x, int d0) {
    uint word = 0u;
    for (int lane = 0; lane < 2; ++lane) {
        int d = d0 + lane;
        if (d <= u_max_disparity && x >= d) {
            int r = i - d;
            uint c = uint(bitCount(codes[4 * i] ^ codes[4 * r + 2]) + bitCount(codes[4 * i + 1] ^ codes[4 * r + 3]));
            word |= c << (16 * lane);
        }
    }
    return word;
}

void main() {
    int y = int(gl_GlobalInvocationID.x);
    int k = int(gl_GlobalInvocationID.y);
    if (y >= u_size.y || k >= u_pairs) {
        return;
    }
    int d0 = u_first_d + 2 * k;
    int row = y * u_size.x;
    int base = k * pixels() + row;
    uint window[BOX];
    uint sum = 0u;
    for (int x = 0; x < BOX_RADIUS && x < u_size.x; ++x) {
        window[x] = cost_word(row + x, x, d0);
        sum += window[x];
    }
    // The slot of the column entering at x + BOX_RADIUS is the one of the column leaving,
    // x - BOX_RADIUS - 1.
    int slot = BOX_RADIUS;
    for (int x = 0; x < u_size.x; ++x) {
        if (x - BOX_RADIUS - 1 >= 0) {
            sum -= window[slot];
        }
        int entering = x + BOX_RADIUS;
        if (entering < u_size.x) {
            window[slot] = cost_word(row + entering, entering, d0);
            sum += window[slot];
        }
        rows[base + x] = sum;
        slot = slot + 1 == BOX ? 0 : slot + 1;
    }
}
