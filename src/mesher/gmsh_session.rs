//! One gmsh session for the meshes of an adaptive sequence: `pipeline/mesh_rod.py serve`, kept
//! running, asked for one mesh per line.
//!
//! A mesh in a fresh process (`mesh_rod.py mesh`, [`super::gmsh`]) starts two Python interpreters
//! (the command and its child, which isolates a gmsh crash) and gmsh, then reads and
//! reparametrises the classified surface. The session starts them once, and after each reply
//! builds the next mesh's model from the cached classification while the caller solves on the
//! other core; each mesh takes the same steps as in a fresh process, the same mesh bit for bit
//! (`tests/gmsh_session.rs` compares the files). It serves the usual route only: its first error
//! ends it, and the caller makes that mesh and the rest in fresh processes, with the ladder of
//! classifications, Delaunay and the fallbacks.

use std::collections::VecDeque;
use std::io::{BufRead, BufReader, Write};
use std::path::Path;
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{Receiver, RecvTimeoutError, channel};
use std::sync::{Arc, Mutex};
use std::time::Instant;

use super::gmsh::{MeshedRod, mesher_timeout, read_reported};
use crate::fem::error::{FemError, Result};

/// Lines of the session's standard error kept for an error message.
const STDERR_TAIL: usize = 15;

/// A running `mesh_rod.py serve` on one STL.
pub struct GmshSession {
    child: Child,
    stdin: Option<ChildStdin>,
    replies: Receiver<String>,
    stderr_tail: Arc<Mutex<VecDeque<String>>>,
}

impl GmshSession {
    /// Starts `python script serve STL --geometry GEOMETRY` (the classified-surface cache, as
    /// `mesh --geometry`). gmsh starts while the caller goes on; the first request waits for it.
    pub fn start(python: &Path, script: &Path, stl: &Path, geometry: &Path) -> Result<Self> {
        if !script.is_file() {
            return Err(FemError::Mesher(format!(
                "mesher script not found: {}",
                script.display()
            )));
        }
        let mut child = Command::new(python)
            .arg(script)
            .arg("serve")
            .arg(stl)
            .arg("--geometry")
            .arg(geometry)
            .arg(super::policy::MeshPolicy::standard().arg())
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| {
                FemError::Mesher(format!(
                    "{} {} serve: {e}",
                    python.display(),
                    script.display()
                ))
            })?;
        let stdout = child.stdout.take().expect("piped");
        let stderr = child.stderr.take().expect("piped");
        let (send, replies) = channel();
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines().map_while(|l| l.ok()) {
                if send.send(line).is_err() {
                    break;
                }
            }
        });
        let stderr_tail = Arc::new(Mutex::new(VecDeque::new()));
        let tail = Arc::clone(&stderr_tail);
        std::thread::spawn(move || {
            for line in BufReader::new(stderr).lines().map_while(|l| l.ok()) {
                let mut t = tail.lock().unwrap_or_else(|p| p.into_inner());
                if t.len() == STDERR_TAIL {
                    t.pop_front();
                }
                t.push_back(line);
            }
        });
        Ok(GmshSession {
            stdin: child.stdin.take(),
            child,
            replies,
            stderr_tail,
        })
    }

    /// One mesh into `out_dir/name.msh`: uniform at `size_mm`, or from `size_field` capped at
    /// `size_mm`; read natively. An error (gmsh's, the session's end, the mesher's time limit)
    /// leaves the session unusable: the caller drops it.
    pub fn mesh(
        &mut self,
        size_mm: f64,
        size_field: Option<&Path>,
        out_dir: &Path,
        name: &str,
    ) -> Result<MeshedRod> {
        let request = serde_json::json!({
            "size": size_mm,
            "size_field": size_field,
            "out_dir": out_dir,
            "name": name,
        });
        let t0 = Instant::now();
        let stdin = self
            .stdin
            .as_mut()
            .ok_or_else(|| FemError::Mesher("the gmsh session has ended".into()))?;
        writeln!(stdin, "{request}")
            .and_then(|_| stdin.flush())
            .map_err(|e| self.failure(format!("cannot ask the gmsh session: {e}")))?;
        let limit = mesher_timeout();
        let reply = match self.replies.recv_timeout(limit) {
            Ok(line) => line,
            Err(RecvTimeoutError::Timeout) => {
                let _ = self.child.kill();
                return Err(self.failure(format!(
                    "the gmsh session was stopped after {:.0} s (the limit; set {} to change it)",
                    limit.as_secs_f64(),
                    super::gmsh::MESHER_TIMEOUT_VAR
                )));
            }
            Err(RecvTimeoutError::Disconnected) => {
                let status = self.child.wait().map(|s| s.to_string()).unwrap_or_default();
                return Err(self.failure(format!("the gmsh session ended ({status})")));
            }
        };
        let secs = t0.elapsed().as_secs_f64();
        let value: serde_json::Value = serde_json::from_str(&reply).map_err(|e| {
            self.failure(format!(
                "cannot parse the gmsh session's reply ({e}): {reply}"
            ))
        })?;
        if let Some(error) = value.get("error").and_then(|e| e.as_str()) {
            return Err(self.failure(format!("gmsh: {error}")));
        }
        read_reported(&reply, secs)
    }

    /// An error with the end of the session's log; the session takes no more requests.
    fn failure(&mut self, what: String) -> FemError {
        self.stdin = None;
        let tail = self.stderr_tail.lock().unwrap_or_else(|p| p.into_inner());
        let log: Vec<&str> = tail.iter().map(String::as_str).collect();
        FemError::Mesher(if log.is_empty() {
            what
        } else {
            format!("{what}; its log ends:\n{}", log.join("\n"))
        })
    }
}

impl Drop for GmshSession {
    /// Ends the session at once: between requests it holds nothing that is not on disk (the
    /// classified-surface cache is written before a reply), and it may be building the model of a
    /// next mesh that will not be asked for.
    fn drop(&mut self) {
        self.stdin = None;
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}
