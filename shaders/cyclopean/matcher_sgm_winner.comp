// Winner takes all on one level's sums, both eyes (the twin's `winner`, `winners_left`,
// `winners_right`): the lowest sum of the pixel's window (ties to the smaller disparity), the
// sums one below and above it and the lowest at least two away. The right pixel x at disparity
// d has the left pixel x + d's sum, where that pixel searched d. Below the pair's level the
// winners guide the next finer one (a pixel without any: its window's middle); at it they are
// stored as the census matcher's winner stage stores them, for the same sub-pixel stage.
layout(std430, STORAGE_BUFFER(0)) readonly buffer Sums {
    uint sums[];
};
layout(std430, STORAGE_BUFFER(1)) readonly buffer Starts {
    uint starts[];
};
layout(std430, STORAGE_BUFFER(2)) writeonly buffer Guides {
    uint guides[];
};
layout(std430, STORAGE_BUFFER(3)) writeonly buffer WinnerLeft {
    uint winner_left[];  // 4 words per pixel, as matcher_winner.comp
};
layout(std430, STORAGE_BUFFER(4)) writeonly buffer WinnerRight {
    uint winner_right[];
};

// The sum of left pixel xl of row `row` (its first index) at disparity d, NO_CELL where xl is
// outside the image, d outside its window, or d > xl.
uint left_sum(int row, int xl, int d) {
    if (xl >= u_size.x || d > xl) {
        return NO_CELL;
    }
    int start = int(starts[2 * (row + xl)]);
    if (d < start || d >= start + u_window) {
        return NO_CELL;
    }
    return sums[(row + xl) * u_window + d - start];
}

// Eye `eye` (0 left, 1 right) of pixel x at disparity d, within its own window [s, s + n).
uint offered(int eye, int row, int x, int s, int d) {
    if (d < s || d >= s + u_window) {
        return NO_CELL;
    }
    return eye == 0 ? left_sum(row, x, d) : left_sum(row, x + d, d);
}

// cost, d, below, above, second
void winner(int eye, int row, int x, int s, out uint best, out uint at, out uint below, out uint above, out uint second) {
    best = NO_CELL;
    at = 0u;
    for (int d = s; d < s + u_window; ++d) {
        uint c = offered(eye, row, x, s, d);
        if (c < best) {
            best = c;
            at = uint(d);
        }
    }
    below = NO_CELL;
    above = NO_CELL;
    second = NO_CELL;
    if (best == NO_CELL) {
        return;
    }
    for (int d = s; d < s + u_window; ++d) {
        if (abs(d - int(at)) >= 2) {
            second = min(second, offered(eye, row, x, s, d));
        }
    }
    if (at > 0u) {
        below = offered(eye, row, x, s, int(at) - 1);
    }
    above = offered(eye, row, x, s, int(at) + 1);
}

uint lane(uint v) {
    return v == NO_CELL ? NO_LANE : v;
}

void main() {
    ivec2 p = this_pixel();
    if (p.x < 0) {
        return;
    }
    int row = p.y * u_size.x;
    int i = row + p.x;
    for (int eye = 0; eye < 2; ++eye) {
        int s = int(starts[2 * i + eye]);
        uint best;
        uint at;
        uint below;
        uint above;
        uint second;
        winner(eye, row, p.x, s, best, at, below, above, second);
        if (u_final == 0) {
            guides[2 * i + eye] = best == NO_CELL ? uint(s + (u_window - 1) / 2) : at;
        } else {
            uvec4 packed_winner = uvec4(lane(best) | (at << 16), lane(below) | (lane(above) << 16), 0u, lane(second));
            if (eye == 0) {
                winner_left[4 * i] = packed_winner.x;
                winner_left[4 * i + 1] = packed_winner.y;
                winner_left[4 * i + 2] = packed_winner.z;
                winner_left[4 * i + 3] = packed_winner.w;
            } else {
                winner_right[4 * i] = packed_winner.x;
                winner_right[4 * i + 1] = packed_winner.y;
                winner_right[4 * i + 2] = packed_winner.z;
                winner_right[4 * i + 3] = packed_winner.w;
            }
        }
    }
}
