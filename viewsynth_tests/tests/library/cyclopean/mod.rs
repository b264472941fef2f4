/// The densify pass against its twin on both executors (two images to a whole frame).
mod densify;
/// The 2-D fill pass against its twin on both executors.
mod fill;
/// The gather pass on the built-in scene: GPU against twin under every convention and depth kind.
mod gather;
/// Given disparities made dense before rendering: the densify pass on ground truth.
mod given_disparities;
/// The census and semi-global matchers against their twins, confidence included.
pub(crate) mod matcher;
/// The splat-gather view on real stereo (Cones), thin structures, estimated disparities.
mod real_pairs;
/// Temporal accumulation against its twin over a sequence.
mod temporal;
/// The checked semi-global matcher (matched or inferred disparities) against the twins on both executors.
mod trust;
