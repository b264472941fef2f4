// One path direction u_direction of one level (the twin's `aggregate`), added into the sums:
// one invocation per path, walking it from the image edge. L(p, d) = C(p, d) + min(L(q, d),
// L(q, d +- 1) + P1, min L(q) + P2') - min L(q), q the previous pixel; q's window may start
// elsewhere, so its disparity d is index d - start(q). Integers only: the twin's sums exactly.
layout(std430, STORAGE_BUFFER(0)) readonly buffer Costs {
    uint costs[];
};
layout(std430, STORAGE_BUFFER(1)) readonly buffer Starts {
    uint starts[];
};
layout(std430, STORAGE_BUFFER(2)) readonly buffer Greys {
    uint greys[];  // left | right << 16
};
layout(std430, STORAGE_BUFFER(3)) buffer Sums {
    uint sums[];
};

// The path from p, any window (the coarsest level's whole search).
void walk(ivec2 p, int dx, int dy) {
    int w = u_size.x;
    int h = u_size.y;
    int n = u_window;
    uint prev[FULL_SEARCH];
    uint cur[FULL_SEARCH];
    uint low = 0u;
    int start_q = 0;
    uint grey_q = 0u;
    bool first = true;
    while (p.x >= 0 && p.x < w && p.y >= 0 && p.y < h) {
        int i = p.y * w + p.x;
        int start = int(starts[2 * i]);
        uint grey = greys[i] & 0xffffu;
        if (first) {
            for (int k = 0; k < n; ++k) {
                cur[k] = costs[i * n + k];
            }
        } else {
            uint p2 = p2_across(grey > grey_q ? grey - grey_q : grey_q - grey);
            int shift = start - start_q;
            for (int k = 0; k < n; ++k) {
                int kq = k + shift;
                uint best = low + p2;
                if (kq >= 0 && kq < n) {
                    best = min(best, prev[kq]);
                }
                if (kq - 1 >= 0 && kq - 1 < n) {
                    best = min(best, prev[kq - 1] + P1);
                }
                if (kq + 1 >= 0 && kq + 1 < n) {
                    best = min(best, prev[kq + 1] + P1);
                }
                cur[k] = costs[i * n + k] + best - low;
            }
        }
        uint next_low = NO_CELL;
        for (int k = 0; k < n; ++k) {
            sums[i * n + k] += cur[k];
            prev[k] = cur[k];
            next_low = min(next_low, cur[k]);
        }
        low = next_low;
        start_q = start;
        grey_q = grey;
        first = false;
        p += ivec2(dx, dy);
    }
}

// The path from p at a finer level (windows of WINDOW cells): the same integers as walk(), with
// the cells in registers (constant trip counts) and the previous pixel's cells picked by
// comparison instead of by an index computed per cell, which llvmpipe turns into per-lane
// stack accesses.
void walk_window(ivec2 p, int dx, int dy) {
    int w = u_size.x;
    int h = u_size.y;
    uint prev[WINDOW];
    uint low = 0u;
    int start_q = 0;
    uint grey_q = 0u;
    bool first = true;
    while (p.x >= 0 && p.x < w && p.y >= 0 && p.y < h) {
        int i = p.y * w + p.x;
        int start = int(starts[2 * i]);
        uint grey = greys[i] & 0xffffu;
        uint cur[WINDOW];
        if (first) {
            for (int k = 0; k < WINDOW; ++k) {
                cur[k] = costs[i * WINDOW + k];
            }
        } else {
            uint p2 = p2_across(grey > grey_q ? grey - grey_q : grey_q - grey);
            int shift = start - start_q;
            for (int k = 0; k < WINDOW; ++k) {
                int kq = k + shift;
                uint best = low + p2;
                for (int j = 0; j < WINDOW; ++j) {
                    if (j == kq) {
                        best = min(best, prev[j]);
                    }
                    if (j == kq - 1 || j == kq + 1) {
                        best = min(best, prev[j] + P1);
                    }
                }
                cur[k] = costs[i * WINDOW + k] + best - low;
            }
        }
        uint next_low = NO_CELL;
        for (int k = 0; k < WINDOW; ++k) {
            sums[i * WINDOW + k] += cur[k];
            prev[k] = cur[k];
            next_low = min(next_low, cur[k]);
        }
        low = next_low;
        start_q = start;
        grey_q = grey;
        first = false;
        p += ivec2(dx, dy);
    }
}

void main() {
    int line = int(gl_WorkGroupID.x) * 64 + int(gl_LocalInvocationIndex);
    int w = u_size.x;
    int h = u_size.y;
    int dx = u_direction.x;
    int dy = u_direction.y;
    // Paths start where the previous pixel is outside: the first column (dy = 0), the first row
    // (dx = 0), or both (diagonals: the first row, then the first column below or above it).
    ivec2 p;
    if (dy == 0) {
        if (line >= h) {
            return;
        }
        p = ivec2(dx > 0 ? 0 : w - 1, line);
    } else if (dx == 0) {
        if (line >= w) {
            return;
        }
        p = ivec2(line, dy > 0 ? 0 : h - 1);
    } else {
        if (line >= w + h - 1) {
            return;
        }
        if (line < w) {
            p = ivec2(line, dy > 0 ? 0 : h - 1);
        } else {
            int j = line - w;
            p = ivec2(dx > 0 ? 0 : w - 1, dy > 0 ? j + 1 : h - 2 - j);
        }
    }
    if (u_window == WINDOW) {
        walk_window(p, dx, dy);
    } else {
        walk(p, dx, dy);
    }
}
