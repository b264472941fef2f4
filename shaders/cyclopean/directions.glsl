// The 16 walk directions of the 2-D passes (densify.frag, fill.frag), the same table as
// DIRECTIONS in src/cyclopean/walk.rs: integer steps, so a walk visits the same texels on every
// API and on the CPU. Step k along d lands on p + k d; its distance is k max(|d.x|, |d.y|).
const int DIRECTION_COUNT = 16;
const ivec2 DIRECTIONS[16] = ivec2[16](
    ivec2(1, 0), ivec2(2, 1), ivec2(1, 1), ivec2(1, 2), ivec2(0, 1), ivec2(-1, 2), ivec2(-1, 1), ivec2(-2, 1),
    ivec2(-1, 0), ivec2(-2, -1), ivec2(-1, -1), ivec2(-1, -2), ivec2(0, -1), ivec2(1, -2), ivec2(1, -1), ivec2(2, -1));
