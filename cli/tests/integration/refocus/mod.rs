/// 16-bit PNG, colour-mapped and other depth outputs.
mod depth_out;
/// The input formats users have: intrinsics files, depth containers, colour storage.
mod formats;
/// Wrong conventions named wherever depth comes in.
mod plausibility;
/// `--rgb-everywhere` on a real frame.
mod rgb_everywhere;
/// Units are never assumed.
mod units;
/// Every option a warning suggests is accepted.
mod warning_flags;
