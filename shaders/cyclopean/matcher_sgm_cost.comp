// One level's cost volume (the twin's `cost_volume`): each pixel's window of u_window
// disparities starts at 0 on the coarsest level, else around twice the coarser level's winner
// at (x / 2, y / 2) (`window_start`); cell k is the Hamming distance of the census codes for
// disparity start + k summed over the box (coordinates clamped), COST_OUTSIDE where x < d. The sums
// the path stage adds into start at 0.
layout(std430, STORAGE_BUFFER(0)) readonly buffer Codes {
    uint codes[];  // per pixel: left low, left high, right low, right high
};
layout(std430, STORAGE_BUFFER(1)) readonly buffer Guides {
    uint guides[];  // the coarser level's winners: left, right per pixel
};
layout(std430, STORAGE_BUFFER(2)) writeonly buffer Starts {
    uint starts[];  // each pixel's first disparity: left eye, right eye
};
layout(std430, STORAGE_BUFFER(3)) writeonly buffer Costs {
    uint costs[];
};
layout(std430, STORAGE_BUFFER(4)) writeonly buffer Sums {
    uint sums[];
};

uint window_start(uint guide) {
    uint half_window = uint(u_window - 1) / 2u;
    uint top = uint(u_max_disparity + 1 - u_window);
    uint centre = 2u * guide;
    return min(centre > half_window ? centre - half_window : 0u, top);
}

void main() {
    ivec2 p = this_pixel();
    if (p.x < 0) {
        return;
    }
    int w = u_size.x;
    int i = p.y * w + p.x;
    uint start_l = 0u;
    uint start_r = 0u;
    if (u_other_size.x > 0) {
        int j = (p.y / 2) * u_other_size.x + p.x / 2;
        start_l = window_start(guides[2 * j]);
        start_r = window_start(guides[2 * j + 1]);
    }
    starts[2 * i] = start_l;
    starts[2 * i + 1] = start_r;
    for (int k = 0; k < u_window; ++k) {
        int d = int(start_l) + k;
        uint cost = 0u;
        if (p.x < d) {
            cost = COST_OUTSIDE;
        } else {
            for (int dy = -COST_RADIUS; dy <= COST_RADIUS; ++dy) {
                int y = clamp(p.y + dy, 0, u_size.y - 1);
                for (int dx = -COST_RADIUS; dx <= COST_RADIUS; ++dx) {
                    int x = clamp(p.x + dx, 0, w - 1);
                    int xr = clamp(x - d, 0, w - 1);
                    int a = 4 * (y * w + x);
                    int b = 4 * (y * w + xr);
                    cost += uint(bitCount(codes[a] ^ codes[b + 2]) + bitCount(codes[a + 1] ^ codes[b + 3]));
                }
            }
        }
        costs[i * u_window + k] = cost;
        sums[i * u_window + k] = 0u;
    }
}
