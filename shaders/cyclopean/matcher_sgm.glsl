// The semi-global matcher's constants (src/cyclopean/matcher/sgm/mod.rs holds the design and
// their Rust values, which a unit test holds this file to; sgm/reference.rs is the CPU twin).
const int COST_RADIUS = 2;
const uint COST_MAX = 850u;
const uint COST_OUTSIDE = 306u;
const uint P1 = 60u;
const uint P2 = 1000u;
const uint EDGE_GREY = 24u;
const int FULL_SEARCH = 64;
const int WINDOW = 5;
const int REPEAT_GAP = 3;
const uint REPEAT_SECOND_PERCENT = 35u;
const uint REPEAT_RIDGE_PERCENT = 30u;
// No cost: the disparity is not searched at the pixel or looks outside the other image.
const uint NO_CELL = 0xffffffffu;

// The twin's `p2_across`: P2 lowered across a grey edge, never below P1 + 1.
uint p2_across(uint dgrey) {
    return dgrey > EDGE_GREY ? max(P2 * EDGE_GREY / dgrey, P1 + 1u) : P2;
}
