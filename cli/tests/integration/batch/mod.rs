/// `--zoom-random` and per-frame augmentation through the binary.
mod augment;
/// Resume by identity: a frame's inputs by size and mtime, else content.
mod identity;
/// Memory per frame is flat on every sequence and batch path.
mod memory_flat;
/// Resume invalidation, shards, the index, `--verify`.
pub(crate) mod resume;
/// `viewsynth manifest` from a TUM-style sequence.
mod tum_manifest;
/// Resume that verifies folders and float settings.
mod verify;
