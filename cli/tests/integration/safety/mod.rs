/// Every count or range the user gives is bounded before the work it implies.
pub(crate) mod bounds;
/// The commit protocol killed or failed after every step: the old set or the new, complete.
mod commit;
/// Symlinks, FIFOs, devices, huge or truncated files, concurrent runs, kill -9 then rerun.
mod files_and_processes;
/// Every input bounded before it is read.
mod inputs_bounded;
/// Refusals name the option or file and the reason.
mod messages;
/// Depth and focal values over the whole float range: never valid and non-finite.
mod numerics;
/// Every option refuses an invalid value with exit 2 naming it; named usage errors.
mod options;
/// Resource limits: full stdout, `ulimit -f/-n/-v`, out of memory at a readback.
mod resource_limits;
/// What the safety tables share.
pub(crate) mod support;
