// The next coarser level's grey levels of both eyes (the twin's `downsample`): the mean of each
// 2 x 2 block of the finer level (u_other_size), rounded half up, the last row and column
// replicated at odd sizes.
layout(std430, STORAGE_BUFFER(0)) readonly buffer Fine {
    uint fine[];  // left | right << 16
};
layout(std430, STORAGE_BUFFER(1)) writeonly buffer Coarse {
    uint coarse[];
};

void main() {
    ivec2 p = this_pixel();
    if (p.x < 0) {
        return;
    }
    ivec2 f = u_other_size;
    int x0 = 2 * p.x;
    int y0 = 2 * p.y;
    int x1 = min(x0 + 1, f.x - 1);
    int y1 = min(y0 + 1, f.y - 1);
    uint a = fine[y0 * f.x + x0];
    uint b = fine[y0 * f.x + x1];
    uint c = fine[y1 * f.x + x0];
    uint d = fine[y1 * f.x + x1];
    uint l = ((a & 0xffffu) + (b & 0xffffu) + (c & 0xffffu) + (d & 0xffffu) + 2u) / 4u;
    uint r = ((a >> 16) + (b >> 16) + (c >> 16) + (d >> 16) + 2u) / 4u;
    coarse[p.y * u_size.x + p.x] = l | (r << 16);
}
