//! The per-design result cache: a second study with nothing changed reuses each design's
//! figures; changing a design's STL or sidecar, the configuration or the program reruns only
//! the designs concerned.
//!
//! The key is the SHA-256 of the program version, the program itself ([`program_fingerprint`]:
//! the running executable and the pipeline's mesher scripts), the configuration (as JSON), the
//! bytes of its pressure trace if it has one, the STL bytes and the sidecar bytes. Entries live in
//! `OUT/.cache/<id>.json` (a study without stage 3: `OUT/.cache/without-fem/<id>.json`), written
//! atomically.

use crate::config::StudyConfig;
use crate::report::atomic_write::write_atomic;
use anyhow::Result;
use serde::{Serialize, de::DeserializeOwned};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// The pipeline scripts whose code stage 1 and stage 3 run.
const PIPELINE_SCRIPTS: [&str; 2] = ["mesh_rod.py", "step_solid.py"];

/// SHA-256 of the program a study runs: the bytes of the running executable and of the pipeline
/// scripts it calls. The version number alone does not change with the code: a study after a
/// change of defaults would reuse results the earlier program had made.
/// Read once per process.
pub fn program_fingerprint() -> &'static [u8] {
    static FINGERPRINT: std::sync::OnceLock<Vec<u8>> = std::sync::OnceLock::new();
    FINGERPRINT.get_or_init(|| {
        fingerprint_of(
            std::env::current_exe().ok().as_deref(),
            &crate::python_env::project_root(),
        )
    })
}

/// SHA-256 of the executable `exe` and of the [`PIPELINE_SCRIPTS`] under `root/pipeline`; a file
/// that cannot be read keys nothing apart (the version still does).
fn fingerprint_of(exe: Option<&Path>, root: &Path) -> Vec<u8> {
    let mut h = Sha256::new();
    if let Some(bytes) = exe.and_then(|e| std::fs::read(e).ok()) {
        h.update(b"executable");
        h.update(bytes);
    }
    for name in PIPELINE_SCRIPTS {
        if let Ok(bytes) = std::fs::read(root.join("pipeline").join(name)) {
            h.update(name.as_bytes());
            h.update(bytes);
        }
    }
    h.finalize().to_vec()
}

/// Content hash of everything a design's results depend on.
pub fn design_key(stl: &Path, config: &StudyConfig) -> Result<String> {
    let mut h = Sha256::new();
    h.update(env!("CARGO_PKG_VERSION").as_bytes());
    h.update(program_fingerprint());
    h.update(serde_json::to_vec(config)?);
    // the configuration names the pressure trace; its content counts too (nothing is added
    // without a trace, so the default study's keys stay as they were)
    if let Some(trace) = config.engine.pressure_trace {
        h.update(b"pressure_trace");
        h.update(std::fs::read(trace.as_path())?);
    }
    h.update(std::fs::read(stl)?);
    // a STEP's fallback, the STL beside it (stages::mass::load), counts too
    if crate::geometry::step::is_step(stl) {
        for ext in ["stl", "STL", "Stl"] {
            if let Ok(bytes) = std::fs::read(stl.with_extension(ext)) {
                h.update(b"stl beside");
                h.update(bytes);
                break;
            }
        }
    }
    let sidecar = crate::geometry::sidecar::sidecar_path(stl);
    if let Ok(bytes) = std::fs::read(&sidecar) {
        h.update(b"sidecar");
        h.update(bytes);
    }
    Ok(h.finalize().iter().map(|b| format!("{b:02x}")).collect())
}

#[derive(Serialize, serde::Deserialize)]
struct Entry<T> {
    key: String,
    value: T,
}

/// A folder of cached values, one JSON file per design id.
pub struct Cache {
    folder: PathBuf,
}

impl Cache {
    pub fn new(out: &Path) -> Self {
        Self::in_folder(&out.join(".cache"))
    }

    /// A cache in `folder` (e.g. `OUT/.cache/without-fem`, a study's without stage 3).
    pub fn in_folder(folder: &Path) -> Self {
        Cache {
            folder: folder.to_path_buf(),
        }
    }

    fn path(&self, id: &str) -> PathBuf {
        self.folder.join(format!("{id}.json"))
    }

    /// The cached value of `id` if it was stored under the same key.
    pub fn get<T: DeserializeOwned>(&self, id: &str, key: &str) -> Option<T> {
        let text = std::fs::read_to_string(self.path(id)).ok()?;
        let entry: Entry<T> = serde_json::from_str(&text).ok()?;
        (entry.key == key).then_some(entry.value)
    }

    pub fn put<T: Serialize>(&self, id: &str, key: &str, value: &T) -> Result<()> {
        let entry = Entry {
            key: key.to_string(),
            value,
        };
        write_atomic(&self.path(id), &serde_json::to_vec(&entry)?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fingerprint follows the mesher script's bytes (and the executable's): a changed
    /// `mesh_rod.py` keys every design apart, the same bytes in another folder do not.
    #[test]
    fn the_program_fingerprint_follows_the_pipeline_scripts() {
        let roots: Vec<tempfile::TempDir> = (0..3).map(|_| tempfile::tempdir().unwrap()).collect();
        for (root, text) in roots.iter().zip(["a = 1\n", "a = 1\n", "a = 2\n"]) {
            std::fs::create_dir(root.path().join("pipeline")).unwrap();
            std::fs::write(root.path().join("pipeline/mesh_rod.py"), text).unwrap();
        }
        let exe = roots[0].path().join("pipeline/mesh_rod.py");
        let f: Vec<Vec<u8>> = roots
            .iter()
            .map(|r| fingerprint_of(None, r.path()))
            .collect();
        assert_eq!(f[0], f[1]);
        assert_ne!(f[0], f[2]);
        assert_ne!(fingerprint_of(Some(&exe), roots[0].path()), f[0]);
        assert_eq!(program_fingerprint().len(), 32);
    }
}
