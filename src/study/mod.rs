//! The study: every stage run on every design of a folder ([`run`]), with a per-design cache
//! ([`cache`]), split into shards and merged back ([`shard`], [`merge`]), and the regression
//! baseline ([`baseline`]). What it found is [`results::StudyResults`]; [`crate::report`] writes
//! the reports. One broken design never stops the others: it is listed with its error and what
//! the stages before the failure computed, and the command's exit status says so.

pub mod baseline;
pub mod cache;
pub mod merge;
pub mod results;
pub mod run;
pub mod shard;

pub use results::{DesignResult, FailedDesign, STAGES, StudyResults};
pub use run::{Progress, StudyOptions, run_study};
