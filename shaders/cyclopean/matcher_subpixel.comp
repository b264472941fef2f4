// Each eye's winner refined by the parabola through its cost and its neighbours' (the twin's
// `Winner::disparity`); 0 = unknown. Every value is an integer below 2^24, exact in f32, and the
// quotient is rebuilt from integers, correctly rounded as the CPU's IEEE division (GLSL allows
// its own division 2.5 ulp), so the result is the twin's bit for bit.
layout(std430, STORAGE_BUFFER(0)) readonly buffer WinnerLeft {
    uint winner_left[];
};
layout(std430, STORAGE_BUFFER(1)) readonly buffer WinnerRight {
    uint winner_right[];
};
layout(std430, STORAGE_BUFFER(2)) writeonly buffer Raw {
    float raw[];  // left eye, then right eye
};

// a / b for b > 0, rounded to the nearest f32 (ties to even) by long division.
float quotient(int a, int b) {
    if (a == 0) {
        return 0.0;
    }
    uint n = uint(abs(a));
    uint m = uint(b);
    int e = 0;
    // Normalise so that m <= n < 2 m: a / b = (n / m) 2^e.
    while (n < m) {
        n <<= 1;
        --e;
    }
    while (n >= 2u * m) {
        m <<= 1;
        ++e;
    }
    uint q = 0u;
    for (int k = 0; k < 24; ++k) {
        q <<= 1;
        if (n >= m) {
            n -= m;
            q |= 1u;
        }
        n <<= 1;
    }
    // q holds the 24 significant bits; n / m is twice the rest.
    if (n > m || (n == m && (q & 1u) == 1u)) {
        q += 1u;
    }
    // An exact power of two (|a| >= 1 and b < 2^16 put e above -17), so the product is exact.
    float v = float(q) * uintBitsToFloat(uint(e - 23 + 127) << 23);
    return a < 0 ? -v : v;
}

// The twin's `unique`: the winner's cost below the second-best's by more than the margin.
bool unique(uint c, uint second) {
    return second == NO_LANE || c * (100u + UNIQUENESS_PERCENT) < second * 100u;
}

float disparity(uint w0, uint w1, uint w3) {
    uint c = w0 & 0xffffu;
    if (c == NO_LANE || !unique(c, w3)) {
        return 0.0;
    }
    float d = float(w0 >> 16);
    uint below = w1 & 0xffffu;
    uint above = w1 >> 16;
    if (below != NO_LANE && above != NO_LANE) {
        int curvature = int(below) - 2 * int(c) + int(above);
        if (curvature > 0) {
            d += clamp(quotient(int(below) - int(above), 2 * curvature), -0.5, 0.5);
        }
    }
    return d;
}

void main() {
    ivec2 p = this_pixel();
    if (p.x < 0) {
        return;
    }
    int i = p.y * u_size.x + p.x;
    raw[i] = disparity(winner_left[4 * i], winner_left[4 * i + 1], winner_left[4 * i + 3]);
    raw[pixels() + i] = disparity(winner_right[4 * i], winner_right[4 * i + 1], winner_right[4 * i + 3]);
}
