//! The parameter block every matcher stage reads, the census stages' and the semi-global ones'
//! alike: its own file so that both GPU drivers ([`super::gpu`], [`super::sgm::gpu`]) use it
//! without importing each other.

crate::param_block! {
    /// Every matcher stage's parameters: shaders/cyclopean/matcher_params.glsl, member for member.
    pub struct MatcherParams("MatcherParams") {
        u_size: [i32; 2],
        u_max_disparity: i32,
        u_first_d: i32,
        u_pairs: i32,
        u_window: i32,
        u_direction: [i32; 2],
        u_other_size: [i32; 2],
        u_final: i32,
        u_pad: i32,
    }
}
