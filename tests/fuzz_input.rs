//! Fuzzing of the input files, kept in the suite: mutations of valid files (truncation, non-finite
//! and huge numbers, byte-order marks, wrong types, wrong array lengths, empty files, binary
//! garbage, repeated, dropped and swapped lines, stray bytes) with a fixed seed and a bounded
//! number of cases, each under a time limit:
//!
//! * decks (`*.inp`): read and solved in-process ([`read_deck_text`], [`solve_model`]);
//! * settings (`rodstudy.toml` and its pressure trace): read in-process ([`StudyConfig::read`]),
//!   then, when accepted, the dynamics stage on a fixed rod with them;
//! * sidecars (`NAME.toml` beside an STL): stage 1 in-process ([`stages::mass`]);
//! * STEP files: `rodstudy mass` as a child (each case starts Python and OpenCASCADE, so few).
//!
//! Every case must end within its limit, without a panic, either accepted (with finite numbers)
//! or refused with a message that names the file (and, for a deck's reading, its line; for the
//! settings, the key in backticks or the line). A message may say NaN only where the input has
//! one. The counts are printed in one line (README "Reliability", docs/testing.md);
//! `FUZZ_VERBOSE=1` prints every case's outcome.

use rodstudy::config::StudyConfig;
use rodstudy::deck::{SolveOptions, read_deck_text, solve_model};
use rodstudy::geometry::primitives::{binary_stl, to_soup, voxel_rod};
use rodstudy::stages;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::mpsc;
use std::time::Duration;

mod common;

const SEED: u64 = 0x5EED_2026_0038;
const DECK_CASES: usize = 2000;
const SETTINGS_CASES: usize = 1500;
const SIDECAR_CASES: usize = 400;
const STEP_CASES: usize = 15;
/// Time limit of one in-process case, and of one STEP case (Python and OpenCASCADE).
const CASE_LIMIT: Duration = Duration::from_secs(20);
const STEP_LIMIT: Duration = Duration::from_secs(90);

/// splitmix64: a fixed, dependency-free sequence.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
    fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
}

/// What replaces a number: non-finite, huge, tiny, negative, zero, and values of the wrong type.
const NUMBERS: &[&str] = &[
    "NaN",
    "nan",
    "inf",
    "-inf",
    "INF",
    "1e300",
    "-1e300",
    "1e309",
    "1E300",
    "1.E300",
    "1e-300",
    "0",
    "-0",
    "-1",
    "-7800",
    "99999999999999999999",
    "1e12",
    "\"steel\"",
    "[1, 2]",
    "true",
    "{a = 1}",
    "",
    "abc",
    "1,2",
    "0x10",
    "1.0D+400",
];

/// Lines to insert: empty data, stray keywords, stray TOML.
const LINES: &[&str] = &[
    ",,,",
    ",",
    "*",
    "**",
    "* ",
    "*NODE",
    "*ELEMENT, TYPE=C3D10",
    "*END STEP",
    "*STEP",
    "[fem]",
    "[engine]",
    "= 1",
    "x = ",
    "units = \"parsec\"",
    "crank_pin = [1, 2]",
    "#",
    "0,0",
    "720,1",
    "pin_axis = [0, 0, 0]",
    "density = -1",
    "\u{feff}",
];

/// Byte positions of the numbers in `text` (a digit run with sign, point and exponent).
fn number_spans(text: &[u8]) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    let mut i = 0;
    while i < text.len() {
        let starts = text[i].is_ascii_digit()
            && (i == 0 || !(text[i - 1].is_ascii_alphanumeric() || text[i - 1] == b'_'));
        if starts {
            let a = if i > 0 && (text[i - 1] == b'-' || text[i - 1] == b'+') {
                i - 1
            } else {
                i
            };
            let mut b = i;
            while b < text.len()
                && (text[b].is_ascii_digit()
                    || matches!(text[b], b'.' | b'e' | b'E')
                    || (matches!(text[b], b'-' | b'+') && matches!(text[b - 1], b'e' | b'E')))
            {
                b += 1;
            }
            spans.push((a, b));
            i = b;
        } else {
            i += 1;
        }
    }
    spans
}

fn lines_of(text: &[u8]) -> Vec<Vec<u8>> {
    text.split(|&b| b == b'\n').map(<[u8]>::to_vec).collect()
}

fn joined(lines: &[Vec<u8>]) -> Vec<u8> {
    lines.join(&b'\n')
}

/// One mutation of `text`, and its name.
fn mutate(rng: &mut Rng, text: &[u8]) -> (Vec<u8>, &'static str) {
    let mut lines = lines_of(text);
    let n = lines.len();
    match rng.below(13) {
        0 => (text[..rng.below(text.len())].to_vec(), "truncated"),
        1..=3 => {
            let spans = number_spans(text);
            if spans.is_empty() {
                return (text.to_vec(), "unchanged");
            }
            let (a, b) = *rng.pick(&spans);
            let mut out = text[..a].to_vec();
            out.extend_from_slice(rng.pick(NUMBERS).as_bytes());
            out.extend_from_slice(&text[b..]);
            (out, "number replaced")
        }
        4 => {
            let mut out = b"\xef\xbb\xbf".to_vec();
            out.extend_from_slice(text);
            (out, "byte-order mark")
        }
        5 => (Vec::new(), "empty"),
        6 => {
            let len = 1 + rng.below(600);
            (
                (0..len).map(|_| rng.next() as u8).collect(),
                "binary garbage",
            )
        }
        7 => {
            let k = rng.below(n);
            let times = 1 + rng.below(3);
            for _ in 0..times {
                lines.insert(k, lines[k].clone());
            }
            (joined(&lines), "line repeated")
        }
        8 => {
            lines.remove(rng.below(n));
            (joined(&lines), "line dropped")
        }
        9 => {
            let (a, b) = (rng.below(n), rng.below(n));
            lines.swap(a, b);
            (joined(&lines), "lines swapped")
        }
        10 => {
            lines.insert(rng.below(n + 1), rng.pick(LINES).as_bytes().to_vec());
            (joined(&lines), "line inserted")
        }
        11 => {
            let mut out = text.to_vec();
            if !out.is_empty() {
                let k = rng.below(out.len());
                out[k] = *rng.pick(&[0x00, 0xff, 0xe4, 0x80, b'"', b'[', b',', b'*', b'=']);
            }
            (out, "byte replaced")
        }
        _ => {
            // an array one element short or long (pins, axis), else a data line cut short
            let arrays: Vec<usize> = (0..n)
                .filter(|&k| lines[k].contains(&b'[') && lines[k].contains(&b','))
                .collect();
            if let Some(&k) = arrays.get(rng.below(arrays.len().max(1))) {
                let l = String::from_utf8_lossy(&lines[k]).into_owned();
                let changed = if rng.below(2) == 0 {
                    let cut = l.rfind(',').unwrap();
                    format!("{}]", &l[..cut])
                } else {
                    l.replacen(']', ", 1.0]", 1)
                };
                lines[k] = changed.into_bytes();
                (joined(&lines), "array length")
            } else {
                let k = rng.below(n);
                if let Some(cut) = lines[k].iter().rposition(|&b| b == b',') {
                    lines[k].truncate(cut);
                }
                (joined(&lines), "data line cut")
            }
        }
    }
}

/// One to three mutations.
fn mutated(rng: &mut Rng, base: &[u8]) -> (Vec<u8>, String) {
    let mut text = base.to_vec();
    let mut names = Vec::new();
    for _ in 0..1 + rng.below(3) {
        let (t, name) = mutate(rng, &text);
        text = t;
        names.push(name);
    }
    (text, names.join(" + "))
}

/// How a case ended.
#[derive(Debug, PartialEq)]
enum Outcome {
    Accepted,
    Refused(String),
    Panicked(String),
    Hung,
}

/// Runs `f` on a thread of its own under [`CASE_LIMIT`] (a hung case's thread is left behind;
/// the test then fails).
fn within_limit(f: impl FnOnce() -> Result<(), String> + Send + 'static) -> Outcome {
    let (tx, rx) = mpsc::channel();
    let handle = std::thread::spawn(move || {
        let r = f();
        let _ = tx.send(());
        r
    });
    match rx.recv_timeout(CASE_LIMIT) {
        Ok(()) | Err(mpsc::RecvTimeoutError::Disconnected) => match handle.join() {
            Ok(Ok(())) => Outcome::Accepted,
            Ok(Err(message)) => Outcome::Refused(message),
            Err(panic) => Outcome::Panicked(
                panic
                    .downcast_ref::<String>()
                    .cloned()
                    .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                    .unwrap_or_default(),
            ),
        },
        Err(mpsc::RecvTimeoutError::Timeout) => Outcome::Hung,
    }
}

#[derive(Default)]
struct Tally {
    cases: usize,
    refused: usize,
    accepted: usize,
    panics: Vec<String>,
    hangs: Vec<String>,
    unclear: Vec<String>,
}

impl Tally {
    /// Counts one case; a refusal is clear when `clear` holds for its message and it says NaN
    /// only where the input has one.
    fn add(&mut self, label: String, input: &[u8], outcome: Outcome, clear: impl Fn(&str) -> bool) {
        self.cases += 1;
        if std::env::var_os("FUZZ_VERBOSE").is_some() {
            println!("{label}: {outcome:?}");
        }
        match outcome {
            Outcome::Accepted => self.accepted += 1,
            Outcome::Refused(m) => {
                if clear(&m) && (says_nan(&String::from_utf8_lossy(input)) || !says_nan(&m)) {
                    self.refused += 1;
                } else {
                    self.unclear.push(format!("{label}: «{m}»"));
                }
            }
            Outcome::Panicked(m) => self.panics.push(format!("{label}: {m}")),
            Outcome::Hung => self.hangs.push(label),
        }
    }
}

/// `nan` as a word of its own (any case), not inside one ("determinant").
fn says_nan(text: &str) -> bool {
    text.to_lowercase()
        .split(|c: char| !c.is_ascii_alphanumeric())
        .any(|w| w == "nan")
}

/// `file:LINE:` somewhere in `m`.
fn names_a_line(m: &str, file: &str) -> bool {
    m.match_indices(&format!("{file}:"))
        .any(|(i, s)| m[i + s.len()..].starts_with(|c: char| c.is_ascii_digit()))
}

fn fuzz_decks(rng: &mut Rng, dir: &Path, tally: &mut Tally) {
    let (base, _, _) = common::cube_deck(
        "*ELASTIC\n210e9, 0.3\n*DENSITY\n7800\n",
        "*CLOAD\n12, 1, 1000.\n*DLOAD\nEALL, GRAV, 9.81, 0, 0, -1\n",
    );
    let path = dir.join("fuzz.inp");
    for case in 0..DECK_CASES {
        let (bytes, how) = mutated(rng, base.as_bytes());
        let text = String::from_utf8_lossy(&bytes).into_owned();
        let p = path.clone();
        let outcome = within_limit(move || {
            let model = read_deck_text(&p, &text).map_err(|e| format!("read: {e}"))?;
            let sol = solve_model(&model, SolveOptions::default())
                .map_err(|e| format!("solve: {}: {e}", p.display()))?;
            let finite = sol.steps.iter().all(|s| {
                s.residual_rel.is_finite()
                    && s.applied_total.iter().all(|v| v.is_finite())
                    && s.s.iter().flatten().all(|v| v.is_finite())
            });
            if finite {
                Ok(())
            } else {
                Err("accepted with a non-finite result".into())
            }
        });
        // a reading error names its line, or the whole file (an empty deck has no elements);
        // a solving error its step or element
        tally.add(format!("deck {case} ({how})"), &bytes, outcome, |m| {
            m.contains("fuzz.inp")
                && (names_a_line(m, "fuzz.inp")
                    || m.contains("fuzz.inp: no ")
                    || (m.starts_with("solve:") && (m.contains("step ") || m.contains("element "))))
        });
    }
}

const SETTINGS: &str = "[driven]\nomega_rad_s = 125.66370614359172\nduration_s = 5.0\nsteps = 5000\n\
gravity = true\n\n[fem]\ntarget_error = 0.03\nmesh_size_mm = 5.0\ninitial_size_mm = 5.0\n\
max_size_mm = 10.0\nmin_size_mm = 0.3\nmax_iterations = 5\nmax_dofs = 400000\nfixed_band_mm = 6.0\n\
youngs_modulus_pa = 210e9\npoisson_ratio = 0.3\nbore_load = \"uniform\"\n\n[criterion]\n\
yield_mpa = 355.0\nsafety_factor = 1.5\n\n[cycle]\nenabled = true\ninstants = 360\n\n[material]\n\
ultimate_mpa = 470.0\nendurance_mpa = 235.0\n\n[engine]\ncrank_radius_mm = 46.0\n\
piston_mass_kg = 5.2269229374\ncrank_mass_kg = 8.9459574505\ncrank_inertia_kgm2 = 0.016438481547370\n\
crank_eccentricity_mm = 5.190636979\ncylinder_bore_mm = 82.0\npressure_trace = \"trace.csv\"\n";

const TRACE: &str = "# a made-up firing trace\ncrank_angle_deg,pressure_bar\n0,60\n15,80\n60,20\n180,2\n\
360,0\n540,1\n690,15\n720,60\n";

fn fuzz_settings(rng: &mut Rng, dir: &Path, rod: &stages::records::DesignMass, tally: &mut Tally) {
    let (config_path, trace_path) = (dir.join("rodstudy.toml"), dir.join("trace.csv"));
    for case in 0..SETTINGS_CASES {
        // the settings mutated, or their trace (a third of the cases)
        let on_trace = rng.below(3) == 0;
        let (bytes, how) = mutated(rng, if on_trace { TRACE } else { SETTINGS }.as_bytes());
        let (settings, trace) = if on_trace {
            (SETTINGS.as_bytes().to_vec(), bytes.clone())
        } else {
            (bytes.clone(), TRACE.as_bytes().to_vec())
        };
        std::fs::write(&config_path, settings).unwrap();
        std::fs::write(&trace_path, trace).unwrap();
        let (p, rod) = (config_path.clone(), rod.clone());
        let outcome = within_limit(move || {
            let config = StudyConfig::read(&p).map_err(|e| format!("{e:#}"))?;
            // accepted settings run: the dynamics of a fixed rod with them
            stages::dynamics::dynamics_with(
                &rod,
                &config.driven_scene(),
                config.driven.gravity,
                &config.engine,
                rodstudy::mechanism::Method::ClosedForm,
            )
            .map(drop)
            .map_err(|e| format!("late, in the dynamics: {e:#}"))
        });
        let what = if on_trace { "trace" } else { "settings" };
        tally.add(format!("{what} {case} ({how})"), &bytes, outcome, |m| {
            !m.starts_with("late")
                && (m.contains("rodstudy.toml") || m.contains("trace.csv"))
                && (m.contains('`') || m.contains("line") || m.contains("row"))
        });
    }
}

fn fuzz_sidecars(rng: &mut Rng, dir: &Path, tally: &mut Tally) {
    let stl = dir.join("rod.stl");
    std::fs::write(&stl, binary_stl(&to_soup(&voxel_rod().0.scaled(1000.0)))).unwrap();
    let base = "name = \"voxel rod\"\nunits = \"mm\"\ndensity = 7800.0\ncrank_pin = [0.0, 0.0, 0.0]\n\
piston_pin = [180.0, 0.0, 0.0]\npin_axis = [0.0, 0.0, 1.0]\n";
    let sidecar = dir.join("rod.toml");
    for case in 0..SIDECAR_CASES {
        let (bytes, how) = mutated(rng, base.as_bytes());
        std::fs::write(&sidecar, &bytes).unwrap();
        let stl = stl.clone();
        let outcome = within_limit(move || {
            let design = stages::mass::load(&stl).map_err(|e| format!("{e:#}"))?;
            let m = stages::mass::mass(&design).map_err(|e| format!("{e:#}"))?;
            if m.mass_kg.is_finite() && m.l1_m.is_finite() && m.i_zz_kgm2.is_finite() {
                Ok(())
            } else {
                Err("accepted with a non-finite result".into())
            }
        });
        tally.add(format!("sidecar {case} ({how})"), &bytes, outcome, |m| {
            m.contains("rod.toml") || m.contains("rod.stl")
        });
    }
}

fn fuzz_steps(rng: &mut Rng, dir: &Path, tally: &mut Tally) {
    let base = common::box_step(dir).into_bytes();
    for case in 0..STEP_CASES {
        let (bytes, how) = mutated(rng, &base);
        let file: PathBuf = dir.join(format!("fuzz{case}.step"));
        std::fs::write(&file, &bytes).unwrap();
        let run = rodstudy::python_env::output_within(
            Command::new(env!("CARGO_BIN_EXE_rodstudy"))
                .args(["mass", "--json"])
                .arg(&file)
                .env("RODSTUDY_MESHER_TIMEOUT_S", "60"),
            STEP_LIMIT,
        );
        let outcome = match run {
            Err(_) => Outcome::Hung,
            Ok(o) => {
                let stderr = String::from_utf8_lossy(&o.stderr).into_owned();
                match o.status.code() {
                    Some(0) => {
                        let v: serde_json::Value =
                            serde_json::from_slice(&o.stdout).unwrap_or_default();
                        let volume = v[0]["volume_m3"].as_f64().unwrap_or(f64::NAN);
                        if volume.is_finite() && volume > 0.0 {
                            Outcome::Accepted
                        } else {
                            Outcome::Refused(format!("accepted without a volume: {stderr}"))
                        }
                    }
                    Some(1) if !stderr.contains("panicked") => Outcome::Refused(stderr),
                    _ => Outcome::Panicked(stderr),
                }
            }
        };
        let name = format!("fuzz{case}.step");
        tally.add(format!("STEP {case} ({how})"), &bytes, outcome, |m| {
            m.contains(&name) && !m.starts_with("accepted")
        });
    }
}

#[test]
fn fuzzed_input_files_are_accepted_or_refused_clearly() {
    let dir = tempfile::tempdir().unwrap();
    let mut rng = Rng(SEED);
    let mut tally = Tally::default();
    let t0 = std::time::Instant::now();
    let rod_stl = dir.path().join("plain.stl");
    std::fs::write(
        &rod_stl,
        binary_stl(&to_soup(&voxel_rod().0.scaled(1000.0))),
    )
    .unwrap();
    let rod = stages::mass::mass(&stages::mass::load(&rod_stl).unwrap()).unwrap();
    let mut counts = Vec::new();
    let mut run = |name: &str, tally: &mut Tally, f: &mut dyn FnMut(&mut Tally)| {
        let before = tally.cases;
        f(tally);
        counts.push(format!("{name} {}", tally.cases - before));
    };
    let d = dir.path();
    run("deck", &mut tally, &mut |t| fuzz_decks(&mut rng, d, t));
    run("settings", &mut tally, &mut |t| {
        fuzz_settings(&mut rng, d, &rod, t)
    });
    run("sidecar", &mut tally, &mut |t| {
        fuzz_sidecars(&mut rng, d, t)
    });
    run("STEP", &mut tally, &mut |t| fuzz_steps(&mut rng, d, t));
    println!(
        "fuzz_input: {} cases ({}), seed {SEED:#x}: {} refused clearly, {} accepted, {} panics, \
         {} hangs, {} unclear refusals; {:.0} s",
        tally.cases,
        counts.join(", "),
        tally.refused,
        tally.accepted,
        tally.panics.len(),
        tally.hangs.len(),
        tally.unclear.len(),
        t0.elapsed().as_secs_f64()
    );
    assert!(
        tally.panics.is_empty(),
        "panics:\n{}",
        tally.panics.join("\n")
    );
    assert!(tally.hangs.is_empty(), "hangs:\n{}", tally.hangs.join("\n"));
    assert!(
        tally.unclear.is_empty(),
        "{} unclear refusals:\n{}",
        tally.unclear.len(),
        tally.unclear.join("\n")
    );
}
