/// The same frame under every convention and colour storage compares equal after conversion.
mod conventions;
/// Distributions and share gates that one stray pixel does not decide.
mod robust;
