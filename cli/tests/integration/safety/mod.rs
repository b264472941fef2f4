/// Every count or range the user gives is bounded before the work it implies.
pub(crate) mod bounds;
/// Tables over every option (exit 2 naming it), every input bounded before reading, the commit
/// protocol killed or failed after every step, float settings and resume.
mod every_option_and_step;
/// Symlinks, FIFOs, devices, huge or truncated files, concurrent runs, kill -9 then rerun.
mod files_and_processes;
/// Refusals name the option or file and the reason.
mod messages;
/// Resource limits: full stdout, `ulimit -f/-n/-v`, out of memory at a readback.
mod resource_limits;
