// The box's vertical sums, then the mean over the box clipped to the image and to x >= d, in
// the twin's fixed point: (sum << MEAN_SHIFT) / pixels, integer division, so exactly the twin's
// value; NO_LANE where the disparity cannot exist (x < d or past the range). One invocation
// per (column, disparity pair) slides the 9-row window down the column (see matcher_rows.comp).
layout(std430, STORAGE_BUFFER(0)) readonly buffer Rows {
    uint rows[];
};
layout(std430, STORAGE_BUFFER(1)) writeonly buffer Means {
    uint means[];  // [pair][pixel], 16-bit lanes
};

const int BOX = 2 * BOX_RADIUS + 1;

// (sum << MEAN_SHIFT) / n, truncated, exactly: the f32 quotient of two integers below 2^24
// (exact operands) is within a few ulp, under 0.2 at these sizes (below 2^20), so its
// truncation is off by at most one, which the integer test corrects. Integer division is
// scalar on CPU drivers and emulated on GPUs; this is one float division and two products.
uint fixed_point_mean(uint sum, uint n) {
    uint a = sum << MEAN_SHIFT;
    uint q = uint(float(a) / float(n));
    if (q * n > a) {
        q -= 1u;
    } else if ((q + 1u) * n <= a) {
        q += 1u;
    }
    return q;
}

void main() {
    int x = int(gl_GlobalInvocationID.x);
    int k = int(gl_GlobalInvocationID.y);
    if (x >= u_size.x || k >= u_pairs) {
        return;
    }
    int base = k * pixels() + x;
    // Per lane: the disparity and the box's width at this column (0: no such disparity here).
    uint widths[2];
    for (int lane = 0; lane < 2; ++lane) {
        int d = u_first_d + 2 * k + lane;
        int lo = max(x - BOX_RADIUS, d);
        int hi = min(x + BOX_RADIUS, u_size.x - 1);
        widths[lane] = (d <= u_max_disparity && x >= d) ? uint(hi - lo + 1) : 0u;
    }
    uint window[BOX];
    uint sum = 0u;
    for (int y = 0; y < BOX_RADIUS && y < u_size.y; ++y) {
        window[y] = rows[base + y * u_size.x];
        sum += window[y];
    }
    int slot = BOX_RADIUS;
    for (int y = 0; y < u_size.y; ++y) {
        if (y - BOX_RADIUS - 1 >= 0) {
            sum -= window[slot];
        }
        int entering = y + BOX_RADIUS;
        if (entering < u_size.y) {
            window[slot] = rows[base + entering * u_size.x];
            sum += window[slot];
        }
        slot = slot + 1 == BOX ? 0 : slot + 1;
        uint box_rows = uint(min(y + BOX_RADIUS, u_size.y - 1) - max(y - BOX_RADIUS, 0) + 1);
        uint word = 0u;
        for (int lane = 0; lane < 2; ++lane) {
            uint mean = NO_LANE;
            if (widths[lane] > 0u) {
                mean = fixed_point_mean((sum >> (16 * lane)) & 0xffffu, widths[lane] * box_rows);
            }
            word |= mean << (16 * lane);
        }
        means[base + y * u_size.x] = word;
    }
}
