// Census codes of both eyes (src/cyclopean/matcher/reference.rs `census`): one bit per
// neighbour of the 7 x 5 window, set where its grey is below the centre's; borders replicated.
// 34 bits as two words; the bit order differs from the twin's, which leaves every Hamming
// distance as it is.
layout(std430, STORAGE_BUFFER(0)) readonly buffer Greys {
    uint greys[];  // left | right << 16
};
layout(std430, STORAGE_BUFFER(1)) writeonly buffer Codes {
    uint codes[];  // per pixel: left low, left high, right low, right high
};

void main() {
    ivec2 p = this_pixel();
    if (p.x < 0) {
        return;
    }
    uint centre = greys[p.y * u_size.x + p.x];
    uint centre_l = centre & 0xffffu;
    uint centre_r = centre >> 16;
    uvec2 left = uvec2(0u);
    uvec2 right = uvec2(0u);
    int k = 0;
    for (int dy = -CENSUS_HALF_H; dy <= CENSUS_HALF_H; ++dy) {
        int y = clamp(p.y + dy, 0, u_size.y - 1);
        for (int dx = -CENSUS_HALF_W; dx <= CENSUS_HALF_W; ++dx) {
            if (dx == 0 && dy == 0) {
                continue;
            }
            uint g = greys[y * u_size.x + clamp(p.x + dx, 0, u_size.x - 1)];
            uint bit_l = (g & 0xffffu) < centre_l ? 1u : 0u;
            uint bit_r = (g >> 16) < centre_r ? 1u : 0u;
            if (k < 32) {
                left.x |= bit_l << k;
                right.x |= bit_r << k;
            } else {
                left.y |= bit_l << (k - 32);
                right.y |= bit_r << (k - 32);
            }
            ++k;
        }
    }
    int i = 4 * (p.y * u_size.x + p.x);
    codes[i] = left.x;
    codes[i + 1] = left.y;
    codes[i + 2] = right.x;
    codes[i + 3] = right.y;
}
