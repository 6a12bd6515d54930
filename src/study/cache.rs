//! The per-design result cache: a second study with nothing changed reuses each design's
//! figures; changing a design's STL or sidecar, the configuration or the program reruns only
//! the designs concerned.
//!
//! The key is the SHA-256 of the program version, the program itself ([`program_fingerprint`]:
//! the running executable and the pipeline's Python code stages 1 and 3 run), the configuration
//! (as JSON), the
//! bytes of its pressure trace if it has one, the STL bytes and the sidecar bytes. Entries live in
//! `OUT/.cache/<id>.json` (a study without stage 3: `OUT/.cache/without-fem/<id>.json`), written
//! atomically.

use crate::config::StudyConfig;
use crate::report::atomic_write::write_atomic;
use anyhow::Result;
use serde::{Serialize, de::DeserializeOwned};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// The pipeline scripts stage 1 and stage 3 run: the mesher, the STEP reader and the design
/// builder the STEP reader imports.
const PIPELINE_SCRIPTS: [&str; 3] = ["mesh_rod.py", "step_solid.py", "make_designs.py"];

/// The packages under `pipeline/` those scripts import: every `.py` file in them counts, so a
/// module added to a package keys the designs apart without a list to keep.
const PIPELINE_PACKAGES: [&str; 2] = ["meshing", "rod_designs"];

/// SHA-256 of the program a study runs: the bytes of the running executable and of the pipeline
/// code it calls ([`PIPELINE_SCRIPTS`], [`PIPELINE_PACKAGES`]). The version number alone does not change with the code: a study after a
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

/// SHA-256 of the executable `exe`, of the [`PIPELINE_SCRIPTS`] under `root/pipeline` and of the
/// `.py` files of its [`PIPELINE_PACKAGES`] (in the order of their names, each keyed by its path
/// in `pipeline/`); a file that cannot be read keys nothing apart (the version still does).
fn fingerprint_of(exe: Option<&Path>, root: &Path) -> Vec<u8> {
    let mut h = Sha256::new();
    if let Some(bytes) = exe.and_then(|e| std::fs::read(e).ok()) {
        h.update(b"executable");
        h.update(bytes);
    }
    let pipeline = root.join("pipeline");
    let mut files: Vec<String> = PIPELINE_SCRIPTS.iter().map(|s| s.to_string()).collect();
    for package in PIPELINE_PACKAGES {
        let mut modules: Vec<String> = std::fs::read_dir(pipeline.join(package))
            .into_iter()
            .flatten()
            .flatten()
            .filter_map(|e| e.file_name().into_string().ok())
            .filter(|name| name.ends_with(".py"))
            .map(|name| format!("{package}/{name}"))
            .collect();
        modules.sort();
        files.extend(modules);
    }
    for name in files {
        if let Ok(bytes) = std::fs::read(pipeline.join(&name)) {
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

    /// A module of a pipeline package counts as the scripts do: changed, added or renamed, it
    /// keys every design apart; a file that is not Python (a `__pycache__` folder, data) does not.
    #[test]
    fn the_program_fingerprint_follows_the_pipeline_packages() {
        let root = tempfile::tempdir().unwrap();
        let package = root.path().join("pipeline/meshing");
        std::fs::create_dir_all(&package).unwrap();
        std::fs::write(package.join("policy.py"), "a = 1\n").unwrap();
        let before = fingerprint_of(None, root.path());
        std::fs::create_dir(package.join("__pycache__")).unwrap();
        std::fs::write(package.join("notes.txt"), "x").unwrap();
        assert_eq!(fingerprint_of(None, root.path()), before);
        std::fs::write(package.join("policy.py"), "a = 2\n").unwrap();
        let changed = fingerprint_of(None, root.path());
        assert_ne!(changed, before);
        std::fs::write(package.join("volume.py"), "").unwrap();
        let added = fingerprint_of(None, root.path());
        assert_ne!(added, changed);
        std::fs::rename(package.join("volume.py"), package.join("volumes.py")).unwrap();
        assert_ne!(fingerprint_of(None, root.path()), added);
        // the same files in another package count apart
        let other = tempfile::tempdir().unwrap();
        let designs = other.path().join("pipeline/rod_designs");
        std::fs::create_dir_all(&designs).unwrap();
        std::fs::write(designs.join("policy.py"), "a = 2\n").unwrap();
        std::fs::write(designs.join("volumes.py"), "").unwrap();
        assert_ne!(
            fingerprint_of(None, other.path()),
            fingerprint_of(None, root.path())
        );
    }
}
