/// `demo` and `report` end to end, their files read back.
pub(crate) mod demo_and_report;
/// `stress --quick`: the table, the JSON, an unknown capability refused.
mod stress;
