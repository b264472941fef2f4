// The 16 walk directions of the 2-D passes (densify.frag, fill.frag) and their one walk, the same
// table and rule as src/cyclopean/walk.rs: integer steps, so a walk visits the same texels on every
// API and on the CPU. Step k along d lands on p + k d; its distance is k max(|d.x|, |d.y|).
const int DIRECTION_COUNT = 16;
const ivec2 DIRECTIONS[16] = ivec2[16](
    ivec2(1, 0), ivec2(2, 1), ivec2(1, 1), ivec2(1, 2), ivec2(0, 1), ivec2(-1, 2), ivec2(-1, 1), ivec2(-2, 1),
    ivec2(-1, 0), ivec2(-2, -1), ivec2(-1, -1), ivec2(-1, -2), ivec2(0, -1), ivec2(1, -2), ivec2(1, -1), ivec2(2, -1));

// Whether a walk stops at texel q: each program that walks defines it (densify: a known
// disparity; fill: a rendered pixel).
bool walk_stops_at(ivec2 q);

// The first texel from p along direction d where walk_stops_at holds, no farther than radius
// (Chebyshev) and inside size: its position q and its distance (Chebyshev), or 0 when there is
// none. The twin is first_along in src/cyclopean/walk.rs.
int first_along(ivec2 p, ivec2 d, ivec2 size, int radius, out ivec2 q) {
    int m = max(abs(d.x), abs(d.y));
    q = p;
    for (int k = 1; k * m <= radius; ++k) {
        ivec2 c = p + k * d;
        if (any(lessThan(c, ivec2(0))) || any(greaterThanEqual(c, size))) {
            return 0;
        }
        if (walk_stops_at(c)) {
            q = c;
            return k * m;
        }
    }
    return 0;
}
