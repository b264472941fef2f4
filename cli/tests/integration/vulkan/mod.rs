/// `--backend vulkan` commands: `info`, `--require-gpu`, refusals.
mod commands;
/// The cyclopean command on Vulkan writes the gather view.
mod cyclopean;
/// The commands and the batch write the same files on Vulkan; the validation layer is clean.
mod passes;
