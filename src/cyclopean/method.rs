//! The methods the cyclopean view is synthesised by, as front ends name them.

use serde::Serialize;

/// How the middle view is synthesised.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum CyclopeanMethod {
    /// Splat each eye's surfaces, refine each pixel on the surface it sees, merge the eyes.
    SplatGather,
    /// One step per eye: the middle ray's point at the fixation distance projected into the
    /// eye, the eye's depth read where it lands taken as the surface (exact only near the
    /// fixation distance; no projection check), the eyes merged by `--blend`.
    Seed,
    /// The seed's step, `--refine-steps` refinement steps and a projection check.
    Refine,
    /// Each eye's depth mesh rendered into the view, the nearest surface wins.
    Forward,
}

impl CyclopeanMethod {
    /// The name `--method` takes.
    pub fn name(self) -> &'static str {
        match self {
            CyclopeanMethod::SplatGather => "splat-gather",
            CyclopeanMethod::Seed => "seed",
            CyclopeanMethod::Refine => "refine",
            CyclopeanMethod::Forward => "forward",
        }
    }
}
