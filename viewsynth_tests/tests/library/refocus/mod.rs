/// GPU against the f64 twin on real RGB-D frames and the synthetic scene.
mod accuracy;
/// The pipelined batch: byte-identical to the synchronous path; shards partition the frames.
mod batch;
/// The same output under every NDC range, reversed-Z and row order.
mod conventions;
/// Degenerate and extreme inputs: finite outputs and a stated rule for each.
mod edge_cases;
/// An independent oracle written from the seed.
mod oracle;
/// `--rgb-everywhere` against its twin.
mod rgb_everywhere;
