//! `viewsynth index`: joins a batch's index parts into `index.jsonl` and says where.

use super::args::IndexArgs;
use anyhow::Result;

pub(crate) fn index(a: &IndexArgs) -> Result<()> {
    let (path, rows) = viewsynth::refocus::batch::join_index(&a.out_dir)?;
    outln!("{}: {rows} targets", path.display());
    Ok(())
}
