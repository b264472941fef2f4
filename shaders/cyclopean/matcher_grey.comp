// Grey = r + g + b (integers, 0..765) of both eyes, one word a pixel (left in the low half), so
// that the census reads each neighbour with one load instead of two texture fetches.
layout(binding = 1) uniform sampler2D u_left;   // RGBA8
layout(binding = 2) uniform sampler2D u_right;  // RGBA8
layout(std430, STORAGE_BUFFER(0)) writeonly buffer Greys {
    uint greys[];
};

uint grey(sampler2D s, ivec2 p) {
    uvec3 c = uvec3(round(texelFetch(s, p, 0).rgb * 255.0));
    return c.r + c.g + c.b;
}

void main() {
    ivec2 p = this_pixel();
    if (p.x < 0) {
        return;
    }
    greys[p.y * u_size.x + p.x] = grey(u_left, p) | (grey(u_right, p) << 16);
}
