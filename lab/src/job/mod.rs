//! The lab's jobs: one validated description per lab command (`bench`, `report`, `stress`), run
//! like the library's own jobs (see [`viewsynth::job`]): options checked before any work, a GPU
//! asked of the [`Host`](viewsynth::job::Host) only when the job is about to render, and every
//! file written all-or-none.

pub mod bench;
pub mod report;
pub mod stress;
