//! Everything that writes: the study's tables (Markdown, CSV, JSON), the ranking and the Pareto
//! front, `index.html`, the plots, the ParaView field files and the stress pictures. It renders
//! the records of [`crate::stages`] and [`crate::study`]; it computes nothing they report.

pub mod atomic_write;
pub mod columns;
pub mod contact_files;
pub mod design_files;
pub mod fatigue_pictures;
pub mod fields;
pub mod index_page;
pub mod mass_properties;
pub mod pareto;
pub mod picture;
pub mod plots;
pub mod rank_row;
pub mod ranking;
pub mod study_report;
pub mod tables;
pub mod vtu;

pub use study_report::write_reports;

/// A design name usable as a folder name.
pub fn file_safe(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}
