// One level's cost volume (the twin's `cost_volume`): each pixel's window of u_window
// disparities starts at 0 on the coarsest level, else around twice the coarser level's winner
// at (x / 2, y / 2) (`window_start`); cell k is the Hamming distance of the census codes for
// disparity start + k summed over the box (coordinates clamped), COST_OUTSIDE where x < d. On the
// coarsest level a repeated texture's cells are then raised to its floor (`repeated_floor`,
// src/stereo/matcher/sgm/mod.rs). The sums the path stage adds into start at 0.
layout(std430, STORAGE_BUFFER(0)) readonly buffer Codes {
    uint codes[];  // per pixel: left low, left high, right low, right high
};
layout(std430, STORAGE_BUFFER(1)) readonly buffer Guides {
    uint guides[];  // the coarser level's winners: left, right per pixel
};
layout(std430, STORAGE_BUFFER(2)) writeonly buffer Starts {
    uint starts[];  // each pixel's first disparity: left eye, right eye
};
layout(std430, STORAGE_BUFFER(3)) buffer Costs {
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

const int BOX = 2 * COST_RADIUS + 1;

// The left and right census codes (both words) at column x of the row starting at `row`.
uvec2 left_code(int row, int x) {
    int a = 4 * (row + x);
    return uvec2(codes[a], codes[a + 1]);
}
uvec2 right_code(int row, int x) {
    int b = 4 * (row + clamp(x, 0, u_size.x - 1));
    return uvec2(codes[b + 2], codes[b + 3]);
}

// The cells of a pixel whose box never leaves the image's columns: the same sums as main's
// general loop (integers: the order of the additions does not matter), but the box's left
// codes are loaded once and its right codes slide one column per disparity (box column m at
// disparity d reads right column x - COST_RADIUS + m - d, which is column m - 1's at d - 1), so
// a cell loads one right code a row instead of the whole box's codes.
void interior_costs(ivec2 p, int i, int start) {
    int rows[BOX];
    uvec2 left[BOX][BOX];
    uvec2 right[BOX][BOX];
    for (int r = 0; r < BOX; ++r) {
        rows[r] = clamp(p.y + r - COST_RADIUS, 0, u_size.y - 1) * u_size.x;
        for (int m = 0; m < BOX; ++m) {
            left[r][m] = left_code(rows[r], p.x - COST_RADIUS + m);
            right[r][m] = right_code(rows[r], p.x - COST_RADIUS + m - start);
        }
    }
    for (int k = 0; k < u_window; ++k) {
        int d = start + k;
        if (k > 0) {
            for (int r = 0; r < BOX; ++r) {
                for (int m = BOX - 1; m > 0; --m) {
                    right[r][m] = right[r][m - 1];
                }
                right[r][0] = right_code(rows[r], p.x - COST_RADIUS - d);
            }
        }
        uint cost = COST_OUTSIDE;
        if (p.x >= d) {
            cost = 0u;
            for (int r = 0; r < BOX; ++r) {
                for (int m = 0; m < BOX; ++m) {
                    uvec2 x = left[r][m] ^ right[r][m];
                    cost += uint(bitCount(x.x) + bitCount(x.y));
                }
            }
        }
        costs[i * u_window + k] = cost;
        sums[i * u_window + k] = 0u;
    }
}

// The cells of a pixel whose box reaches past the image's columns: the general loop.
void border_costs(ivec2 p, int i, int start) {
    int w = u_size.x;
    for (int k = 0; k < u_window; ++k) {
        int d = start + k;
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

// The twin's `repeated_floor` over the m cells from `base` (disparities 0..m-1), or NO_CELL.
bool local_min(int base, int k, int m, uint c) {
    return (k == 0 || c <= costs[base + k - 1]) && (k + 1 == m || c <= costs[base + k + 1]);
}

uint repeated_floor(int base, int m) {
    if (m < 2 * REPEAT_GAP + 1) {
        return NO_CELL;
    }
    int d1 = 0;
    uint m1 = costs[base];
    uint total = 0u;
    for (int k = 0; k < m; ++k) {
        uint c = costs[base + k];
        total += c;
        if (c < m1) {
            d1 = k;
            m1 = c;
        }
    }
    uint spread = total - m1 * uint(m);
    uint second = NO_CELL;
    // Each side of the lowest cost, walking away from it with the ridge between.
    for (int side = 0; side < 2; ++side) {
        int step = side == 0 ? 1 : -1;
        uint ridge = m1;
        for (int k = d1 + step; k >= 0 && k < m; k += step) {
            uint c = costs[base + k];
            ridge = max(ridge, c);
            if (abs(k - d1) >= REPEAT_GAP && local_min(base, k, m, c) &&
                (ridge - c) * 100u * uint(m) >= REPEAT_RIDGE_PERCENT * spread) {
                second = min(second, c);
            }
        }
    }
    return (second != NO_CELL && (second - m1) * 100u * uint(m) < REPEAT_SECOND_PERCENT * spread) ? second : NO_CELL;
}

void flatten_repeated(int i, int x) {
    int base = i * u_window;
    int m = min(x + 1, u_window);
    uint floor_cost = repeated_floor(base, m);
    if (floor_cost != NO_CELL) {
        for (int k = 0; k < m; ++k) {
            costs[base + k] = max(costs[base + k], floor_cost);
        }
    }
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
    if (p.x >= COST_RADIUS && p.x < w - COST_RADIUS) {
        interior_costs(p, i, int(start_l));
    } else {
        border_costs(p, i, int(start_l));
    }
    // The coarsest level (no coarser guide): every window starts at 0.
    if (u_other_size.x == 0) {
        flatten_repeated(i, p.x);
    }
}
