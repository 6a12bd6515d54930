//! The per-design result cache: a second study with nothing changed reuses each design's
//! figures; changing a design's STL or sidecar, the configuration or the program reruns only
//! the designs concerned.
//!
//! The key is the SHA-256 of the program version, the configuration (as JSON), the bytes of its
//! pressure trace if it has one, the STL bytes and the sidecar bytes. Entries live in `OUT/.cache/<id>.json` (a study without stage 3:
//! `OUT/.cache/without-fem/<id>.json`), written atomically.

use crate::config::StudyConfig;
use crate::report::atomic_write::write_atomic;
use anyhow::Result;
use serde::{Serialize, de::DeserializeOwned};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// Content hash of everything a design's results depend on.
pub fn design_key(stl: &Path, config: &StudyConfig) -> Result<String> {
    let mut h = Sha256::new();
    h.update(env!("CARGO_PKG_VERSION").as_bytes());
    h.update(serde_json::to_vec(config)?);
    // the configuration names the pressure trace; its content counts too (nothing is added
    // without a trace, so the default study's keys stay as they were)
    if let Some(trace) = config.engine.pressure_trace {
        h.update(b"pressure_trace");
        h.update(std::fs::read(trace.as_path())?);
    }
    h.update(std::fs::read(stl)?);
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
