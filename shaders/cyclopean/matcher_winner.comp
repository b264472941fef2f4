// Winner takes all over one chunk of disparities, for both eyes (the twin's `Winner::offer`):
// each eye's pixel is offered its disparities in increasing order; a lower cost wins (a tie
// keeps the smaller disparity) and takes the cost one disparity below it; the cost one above
// the winner is kept when it is offered next; a cost two or more disparities from the winner
// lowers the second-best (for the uniqueness test), which a new winner takes from the running
// minimum of the costs offered up to two disparities before it. The right pixel x sees the
// left pixel x + d at disparity d. The state carries over between chunks in 16-bit lanes:
// word 0 the cost and its disparity, word 1 the costs below and above, word 2 the last cost
// offered and the trailing minimum, word 3 the second-best.
layout(std430, STORAGE_BUFFER(0)) readonly buffer Means {
    uint means[];
};
layout(std430, STORAGE_BUFFER(1)) buffer WinnerLeft {
    uint winner_left[];  // 4 words per pixel
};
layout(std430, STORAGE_BUFFER(2)) buffer WinnerRight {
    uint winner_right[];
};

struct Winner {
    uint cost;
    uint d;
    uint below;
    uint above;
    uint last;
    uint trailing;
    uint second;
};

Winner unpack_winner(uvec4 w) {
    if (u_first_d == 0) {
        return Winner(NO_LANE, 0u, NO_LANE, NO_LANE, NO_LANE, NO_LANE, NO_LANE);
    }
    return Winner(w.x & 0xffffu, w.x >> 16, w.y & 0xffffu, w.y >> 16, w.z & 0xffffu, w.z >> 16, w.w);
}

uvec4 pack_winner(Winner w) {
    return uvec4(w.cost | (w.d << 16), w.below | (w.above << 16), w.last | (w.trailing << 16), w.second);
}

// The mean at pixel i for disparity d of this chunk.
uint mean_at(int i, int d) {
    int j = d - u_first_d;
    return (means[(j >> 1) * pixels() + i] >> (16 * (j & 1))) & 0xffffu;
}

void offer(inout Winner w, int d, uint cost) {
    uint far = w.trailing;  // every cost offered at d - 2 or before
    if (cost < w.cost) {
        w.cost = cost;
        w.d = uint(d);
        w.below = w.last;
        w.above = NO_LANE;
        w.second = far;
    } else if (w.cost != NO_LANE && w.d + 1u == uint(d)) {
        w.above = cost;
    } else {
        w.second = min(w.second, cost);
    }
    w.trailing = min(far, w.last);
    w.last = cost;
}

void main() {
    ivec2 p = this_pixel();
    if (p.x < 0) {
        return;
    }
    int i = p.y * u_size.x + p.x;
    int last_d = min(u_first_d + 2 * u_pairs - 1, u_max_disparity);
    Winner l = unpack_winner(uvec4(winner_left[4 * i], winner_left[4 * i + 1], winner_left[4 * i + 2], winner_left[4 * i + 3]));
    Winner r = unpack_winner(
        uvec4(winner_right[4 * i], winner_right[4 * i + 1], winner_right[4 * i + 2], winner_right[4 * i + 3]));
    for (int d = u_first_d; d <= last_d; ++d) {
        if (p.x >= d) {
            offer(l, d, mean_at(i, d));
        }
        if (p.x + d < u_size.x) {
            offer(r, d, mean_at(i + d, d));
        }
    }
    uvec4 wl = pack_winner(l);
    uvec4 wr = pack_winner(r);
    for (int k = 0; k < 4; ++k) {
        winner_left[4 * i + k] = wl[k];
        winner_right[4 * i + k] = wr[k];
    }
}
