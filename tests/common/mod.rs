//! Helpers shared by the end-to-end tests.

use std::path::Path;

/// Copies design `stem` (its STL and sidecar) from folder `from` into folder `to`.
pub fn copy_design(from: &Path, to: &Path, stem: &str) {
    for ext in ["stl", "toml"] {
        std::fs::copy(
            from.join(format!("{stem}.{ext}")),
            to.join(format!("{stem}.{ext}")),
        )
        .unwrap();
    }
}
