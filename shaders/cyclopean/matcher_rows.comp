// The box's horizontal sums: each cost word summed over the 9 columns around the pixel that
// lie in the image (both lanes at once; the pixels left of x = d hold 0, so the sum is the
// twin's over the box clipped to x >= d).
layout(std430, STORAGE_BUFFER(0)) readonly buffer Costs {
    uint costs[];
};
layout(std430, STORAGE_BUFFER(1)) writeonly buffer Rows {
    uint rows[];
};

void main() {
    ivec2 p = this_pixel();
    if (p.x < 0) {
        return;
    }
    int row = p.y * u_size.x;
    int x0 = max(p.x - BOX_RADIUS, 0);
    int x1 = min(p.x + BOX_RADIUS, u_size.x - 1);
    for (int k = 0; k < u_pairs; ++k) {
        int base = k * pixels() + row;
        uint sum = 0u;
        for (int x = x0; x <= x1; ++x) {
            sum += costs[base + x];
        }
        rows[base + p.x] = sum;
    }
}
