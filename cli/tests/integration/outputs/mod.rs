/// What a run may delete: only what a file it wrote lists.
mod deletion;
/// Every file-writing command writes exactly the files its help names.
mod files_per_output;
/// A user's file at an output name and the previous set's leftovers are refused by name.
mod not_ours;
/// Outputs never land on inputs or on each other; the previous set's leftovers go at commit.
pub(crate) mod over_inputs_and_leftovers;
/// What a user's terminal sees: closed streams, summaries.
mod terminal;
