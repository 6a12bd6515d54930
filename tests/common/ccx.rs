//! CalculiX beside `rodstudy solve` for the deck tests: ccx run on a deck, its printed
//! displacements, totals, buckling factors and eigenvalues (.dat) and nodal blocks (.frd) read
//! back; `rodstudy solve --json` on the same deck.
#![allow(dead_code)]

use std::collections::HashMap;
use std::path::Path;
use std::process::Command;

/// ccx's .dat and .frd of `deck`: per printed set its displacements, totals, the eigenvalue
/// table, and the frd's nodal blocks (name → node → values).
pub struct Ccx {
    pub u: HashMap<i64, [f64; 3]>,
    pub totals: HashMap<String, [f64; 3]>,
    pub buckling: Vec<f64>,
    pub eigen: Vec<f64>,
    pub frd: HashMap<String, HashMap<i64, Vec<f64>>>,
}

pub fn run_ccx(deck: &Path) -> Ccx {
    let dir = deck.parent().unwrap();
    let job = deck.file_stem().unwrap().to_str().unwrap();
    let ccx = std::env::var_os("PATH")
        .and_then(|p| {
            std::env::split_paths(&p)
                .map(|d| d.join("ccx"))
                .find(|p| p.is_file())
        })
        .expect("CalculiX `ccx` on PATH (Debian: apt-get install calculix-ccx)");
    let run = Command::new(ccx)
        .args(["-i", job])
        .current_dir(dir)
        .env("OMP_NUM_THREADS", "1")
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "ccx: {}",
        String::from_utf8_lossy(&run.stdout)
    );
    let dat = std::fs::read_to_string(dir.join(format!("{job}.dat"))).unwrap();
    let mut out = Ccx {
        u: HashMap::new(),
        totals: HashMap::new(),
        buckling: Vec::new(),
        eigen: Vec::new(),
        frd: HashMap::new(),
    };
    let mut block = String::new();
    for l in dat.lines() {
        let t = l.trim();
        if t.is_empty() {
            continue;
        }
        let words: Vec<&str> = t.split_whitespace().collect();
        if t.starts_with("displacements") {
            block = "U".into();
        } else if t.starts_with("total force") {
            block = format!(
                "T {}",
                words[words.iter().position(|w| *w == "set").unwrap() + 1]
            );
        } else if t.starts_with("B U C K L I N G") {
            block = "B".into();
        } else if t.starts_with("E I G E N V A L U E   O U T P U T") {
            block = "F".into();
        } else if t
            .chars()
            .next()
            .is_some_and(|c| c.is_ascii_alphabetic() || c == '(')
        {
            // the eigenvalue tables' column headers keep the block; the next spaced-out title
            // ("P A R T I C I P A T I O N") or any other title ends it
            let spaced = t.as_bytes().get(1) == Some(&b' ');
            if !matches!(block.as_str(), "B" | "F") || spaced {
                block.clear();
            }
        } else {
            let v: Vec<f64> = words.iter().filter_map(|w| w.parse().ok()).collect();
            match block.as_str() {
                "U" => {
                    out.u.insert(words[0].parse().unwrap(), [v[1], v[2], v[3]]);
                }
                "B" if v.len() == 2 => out.buckling.push(v[1]),
                "F" if v.len() >= 4 => out.eigen.push(v[1]),
                b if b.starts_with("T ") => {
                    out.totals.insert(b[2..].to_string(), [v[0], v[1], v[2]]);
                }
                _ => {}
            }
        }
    }
    let frd = std::fs::read_to_string(dir.join(format!("{job}.frd"))).unwrap();
    let mut name = String::new();
    for l in frd.lines() {
        if let Some(rest) = l.strip_prefix(" -4") {
            name = rest.split_whitespace().next().unwrap_or("").to_string();
        } else if l.starts_with(" -3") {
            name.clear();
        } else if !name.is_empty() && l.starts_with(" -1") {
            let node: i64 = l[3..13].trim().parse().unwrap();
            let v: Vec<f64> = (0..(l.len() - 13) / 12)
                .map(|i| l[13 + 12 * i..25 + 12 * i].trim().parse().unwrap())
                .collect();
            out.frd.entry(name.clone()).or_default().insert(node, v);
        }
    }
    out
}

pub fn solve(deck: &Path) -> serde_json::Value {
    let run = Command::new(env!("CARGO_BIN_EXE_rodstudy"))
        .arg("solve")
        .arg(deck)
        .arg("--out")
        .arg(deck.with_extension("out"))
        .args(["--json", "--extrapolation", "calculix"])
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "rodstudy solve {}: {}",
        deck.display(),
        String::from_utf8_lossy(&run.stderr)
    );
    serde_json::from_slice(&run.stdout).unwrap()
}

/// The largest magnitude.
pub fn max_abs<'a>(v: impl Iterator<Item = &'a f64>) -> f64 {
    v.fold(0.0f64, |m, x| m.max(x.abs()))
}
