// Census codes of both eyes (src/cyclopean/matcher/reference.rs `census`): one bit per
// neighbour of the 7 x 5 window, set where its grey (r + g + b, integers) is below the centre's;
// borders replicated. 34 bits as two words; the bit order differs from the twin's, which leaves
// every Hamming distance as it is.
layout(binding = 1) uniform sampler2D u_left;   // RGBA8
layout(binding = 2) uniform sampler2D u_right;  // RGBA8
layout(std430, STORAGE_BUFFER(0)) writeonly buffer Codes {
    uint codes[];  // per pixel: left low, left high, right low, right high
};

int grey(sampler2D s, ivec2 p) {
    ivec3 c = ivec3(round(texelFetch(s, p, 0).rgb * 255.0));
    return c.r + c.g + c.b;
}

uvec2 census(sampler2D s, ivec2 p) {
    int centre = grey(s, p);
    uvec2 code = uvec2(0u);
    int k = 0;
    for (int dy = -CENSUS_HALF_H; dy <= CENSUS_HALF_H; ++dy) {
        for (int dx = -CENSUS_HALF_W; dx <= CENSUS_HALF_W; ++dx) {
            if (dx == 0 && dy == 0) {
                continue;
            }
            ivec2 q = clamp(p + ivec2(dx, dy), ivec2(0), u_size - 1);
            if (grey(s, q) < centre) {
                if (k < 32) {
                    code.x |= 1u << k;
                } else {
                    code.y |= 1u << (k - 32);
                }
            }
            ++k;
        }
    }
    return code;
}

void main() {
    ivec2 p = this_pixel();
    if (p.x < 0) {
        return;
    }
    int i = 4 * (p.y * u_size.x + p.x);
    uvec2 l = census(u_left, p);
    uvec2 r = census(u_right, p);
    codes[i] = l.x;
    codes[i + 1] = l.y;
    codes[i + 2] = r.x;
    codes[i + 3] = r.y;
}
