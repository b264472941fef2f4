//! The lab's jobs: one validated description per lab command (`bench`, `report`, `stress`), run
//! like the library's own jobs (see [`viewsynth::job`]): options checked before any work, a GPU
//! asked of the [`LabHost`] only when the job is about to render, and every file written
//! all-or-none. The lab's own refusals, failures and events are here ([`ArgError`],
//! [`JobError`], [`LabEvent`]), not in the library.

mod error;
mod host;

pub mod bench;
pub mod report;
pub mod stress;

pub use error::{ArgError, JobError};
pub use host::{HostStages, LabEvent, LabHost};
