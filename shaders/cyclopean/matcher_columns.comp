// The box's vertical sums, then the mean over the box clipped to the image and to x >= d, in
// the twin's fixed point: (sum << MEAN_SHIFT) / pixels, integer division, so exactly the
// twin's value. NO_LANE where the disparity cannot exist (x < d or past the range).
layout(std430, STORAGE_BUFFER(0)) readonly buffer Rows {
    uint rows[];
};
layout(std430, STORAGE_BUFFER(1)) writeonly buffer Means {
    uint means[];  // [pair][pixel], 16-bit lanes
};

void main() {
    ivec2 p = this_pixel();
    if (p.x < 0) {
        return;
    }
    int y0 = max(p.y - BOX_RADIUS, 0);
    int y1 = min(p.y + BOX_RADIUS, u_size.y - 1);
    uint box_rows = uint(y1 - y0 + 1);
    for (int k = 0; k < u_pairs; ++k) {
        int base = k * pixels() + p.x;
        uint sum = 0u;
        for (int y = y0; y <= y1; ++y) {
            sum += rows[base + y * u_size.x];
        }
        uint word = 0u;
        for (int lane = 0; lane < 2; ++lane) {
            int d = u_first_d + 2 * k + lane;
            uint mean = NO_LANE;
            if (d <= u_max_disparity && p.x >= d) {
                int lo = max(p.x - BOX_RADIUS, d);
                int hi = min(p.x + BOX_RADIUS, u_size.x - 1);
                uint s = (sum >> (16 * lane)) & 0xffffu;
                mean = (s << MEAN_SHIFT) / (uint(hi - lo + 1) * box_rows);
            }
            word |= mean << (16 * lane);
        }
        means[k * pixels() + p.y * u_size.x + p.x] = word;
    }
}
