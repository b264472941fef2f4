// Each known pixel replaced by the median of the known values in its 3 x 3 neighbourhood (the
// mean of the two middle ones for an even count); unknown pixels stay 0 (the twin's
// `median_of_known`). Sorting moves values unchanged and the mean of two is one rounded sum
// halved, exact as on the CPU.
layout(std430, STORAGE_BUFFER(0)) readonly buffer Checked {
    float checked[];  // left eye, then right eye
};
layout(std430, STORAGE_BUFFER(1)) writeonly buffer Final {
    float final_disparity[];  // the outputs again, for the confidence stage
};
layout(r32f, STORAGE_IMAGE(0)) writeonly uniform image2D u_left_disparity;
layout(r32f, STORAGE_IMAGE(1)) writeonly uniform image2D u_right_disparity;

float median_of_known(int base, ivec2 p) {
    if (checked[base + p.y * u_size.x + p.x] <= 0.0) {
        return 0.0;
    }
    float v[9];
    int m = 0;
    for (int y = max(p.y - 1, 0); y <= min(p.y + 1, u_size.y - 1); ++y) {
        for (int x = max(p.x - 1, 0); x <= min(p.x + 1, u_size.x - 1); ++x) {
            float c = checked[base + y * u_size.x + x];
            if (c > 0.0) {
                int j = m;
                while (j > 0 && v[j - 1] > c) {
                    v[j] = v[j - 1];
                    --j;
                }
                v[j] = c;
                ++m;
            }
        }
    }
    if (m % 2 == 1) {
        return v[m / 2];
    }
    precise float mid = 0.5 * (v[m / 2 - 1] + v[m / 2]);
    return mid;
}

void main() {
    ivec2 p = this_pixel();
    if (p.x < 0) {
        return;
    }
    float l = median_of_known(0, p);
    float r = median_of_known(pixels(), p);
    int i = p.y * u_size.x + p.x;
    final_disparity[i] = l;
    final_disparity[pixels() + i] = r;
    imageStore(u_left_disparity, p, vec4(l, 0.0, 0.0, 0.0));
    imageStore(u_right_disparity, p, vec4(r, 0.0, 0.0, 0.0));
}
