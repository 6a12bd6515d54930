//! What `rodstudy solve` refuses in a deck, by file and line, and what it reads: physically
//! impossible material data (E ≤ 0, ν outside (−1, 0.5), a negative density), a data line without
//! data, a node listed twice by one element (named by the deck's element id), coordinates beyond
//! any model and corners at one place, a load beyond any
//! physical one (where the solution's norms leave f64) and a solution that overflows all the
//! same (never blamed on the supports); a UTF-8 byte-order mark and a Latin-1 byte in a comment
//! are read; a closed standard output ends `solve --json` quietly.

use rodstudy::deck::{SolveOptions, read_deck_text, solve_model};
use std::path::Path;
use std::process::{Command, Stdio};

mod common;
use common::cube_deck as cube;

const STEEL: &str = "*ELASTIC\n210e9, 0.3\n*DENSITY\n7800\n";
/// The far corner (1, 1, 1) is node 12 of the 3 × 2 × 2 corner grid, pulled along x.
const PULL: &str = "*CLOAD\n12, 1, 1000.\n";

fn refusal(text: &str) -> String {
    match read_deck_text(Path::new("cube.inp"), text) {
        Err(e) => e.to_string(),
        Ok(model) => match solve_model(&model, SolveOptions::default()) {
            Err(e) => e.to_string(),
            Ok(_) => panic!("the deck was solved:\n{text}"),
        },
    }
}

#[test]
fn the_cube_solves() {
    // the reference: the same deck with physical data is accepted (so that each refusal below
    // is the defect's)
    let (text, _, _) = cube(STEEL, PULL);
    let model = read_deck_text(Path::new("cube.inp"), &text).unwrap();
    let sol = solve_model(&model, SolveOptions::default()).unwrap();
    assert!(sol.steps[0].residual_rel < 1e-9);
    let (text, _, _) = cube(STEEL, "*DLOAD\nEALL, GRAV, 9.81, 0, 0, -1\n");
    let model = read_deck_text(Path::new("cube.inp"), &text).unwrap();
    assert!(solve_model(&model, SolveOptions::default()).is_ok());
}

#[test]
fn impossible_material_data_is_refused_with_its_line() {
    for (material, defect) in [
        (
            "*ELASTIC\n-210e9, 0.3\n*DENSITY\n7800\n",
            "Young's modulus -210000000000 is not positive",
        ),
        (
            "*ELASTIC\n0, 0.3\n*DENSITY\n7800\n",
            "Young's modulus 0 is not positive",
        ),
        (
            "*ELASTIC\n210e9, 0.5\n*DENSITY\n7800\n",
            "Poisson's ratio 0.5 lies outside (−1, 0.5)",
        ),
        (
            "*ELASTIC\n210e9, -1.5\n*DENSITY\n7800\n",
            "Poisson's ratio -1.5 lies outside",
        ),
    ] {
        let (text, line, _) = cube(material, PULL);
        let e = refusal(&text);
        assert!(e.contains(&format!("cube.inp:{line}: {defect}")), "{e}");
    }
    // a negative density under GRAV, named on its line (the line after *DENSITY)
    let (text, line, _) = cube(
        "*ELASTIC\n210e9, 0.3\n*DENSITY\n-7800\n",
        "*DLOAD\nEALL, GRAV, 9.81, 0, 0, -1\n",
    );
    let e = refusal(&text);
    assert!(
        e.contains(&format!("cube.inp:{}: density -7800 is negative", line + 2)),
        "{e}"
    );
}

#[test]
fn malformed_data_lines_are_refused_with_their_line() {
    let (text, _, first) = cube(STEEL, PULL);
    // a line of empty fields between two element lines
    let mut lines: Vec<&str> = text.lines().collect();
    lines.insert(first, ",,,");
    let e = refusal(&(lines.join("\n") + "\n"));
    assert!(
        e.contains(&format!(
            "cube.inp:{}: a data line of *ELEMENT without data",
            first + 1
        )),
        "{e}"
    );
    // an empty field inside an element line
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    lines[first - 1] = lines[first - 1].replacen(", ", ", , ", 2);
    let e = refusal(&(lines.join("\n") + "\n"));
    assert!(
        e.contains(&format!(
            "cube.inp:{first}: an empty field in an element line"
        )),
        "{e}"
    );
    // a node listed twice by element 1: the deck's id and line, not the element's position
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let line = lines[first - 1].clone();
    let fields: Vec<&str> = line.split(", ").collect();
    let twice = format!("{}, {}, {}", fields[0], fields[1], fields[1]);
    let rest = fields[3..].join(", ");
    lines[first - 1] = format!("{twice}, {rest}");
    let e = refusal(&(lines.join("\n") + "\n"));
    let want = format!("cube.inp:{first}: element 1 lists node {} twice", fields[1]);
    assert!(e.contains(&want), "«{want}» in «{e}»");
}

/// Coordinates no model has, and an element whose corners sit at one place (1e-300 apart: the
/// distance underflows), named by line and the deck's ids.
#[test]
fn absurd_coordinates_and_coinciding_corners_are_refused_with_their_line() {
    let (text, _, first) = cube(STEEL, PULL);
    let node_line = |id: usize| {
        text.lines()
            .position(|l| l.starts_with(&format!("{id}, ")))
            .unwrap()
    };
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let k = node_line(2);
    lines[k] = "2, 1e300, 0.0, 0.0".into();
    let e = refusal(&(lines.join("\n") + "\n"));
    assert!(
        e.contains(&format!("cube.inp:{}: x 1e300 is beyond any model", k + 1)),
        "{e}"
    );
    // element 1's first two corners moved to 1e-300 apart
    let element: Vec<String> = text
        .lines()
        .nth(first - 1)
        .unwrap()
        .split(", ")
        .map(String::from)
        .collect();
    let (a, b) = (
        element[1].parse::<usize>().unwrap(),
        element[2].parse::<usize>().unwrap(),
    );
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let pa: Vec<String> = lines[node_line(a)].split(", ").map(String::from).collect();
    lines[node_line(b)] = format!(
        "{b}, {}, {}, {}",
        pa[1],
        pa[2],
        pa[3].parse::<f64>().unwrap() + 1e-300
    );
    let e = refusal(&(lines.join("\n") + "\n"));
    assert!(
        e.contains(&format!(
            "cube.inp:{first}: element 1: its corners 1 and 2 (nodes {a} and {b}) coincide"
        )),
        "{e}"
    );
}

#[test]
fn an_overflowing_load_is_named_not_blamed_on_the_supports() {
    let (text, _, _) = cube(STEEL, "*CLOAD\n12, 1, 1e300\n");
    let line = text.lines().position(|l| l.contains("1e300")).unwrap() + 1;
    let e = refusal(&text);
    assert!(
        e.contains(&format!("cube.inp:{line}: load 1e300 is beyond any load")),
        "{e}"
    );
    // finite loads whose solution overflows all the same (an absurd modulus and load): the
    // message says so and names the cards to check, not the supports
    let (text, _, _) = cube("*ELASTIC\n1e-300, 0.3\n", "*CLOAD\n12, 1, 1e99\n");
    let e = refusal(&text);
    assert!(!e.contains("rigid-body"), "{e}");
    assert!(e.contains("overflows") && e.contains("*ELASTIC"), "{e}");
}

#[test]
fn a_byte_order_mark_and_a_latin1_comment_are_read() {
    let dir = tempfile::tempdir().unwrap();
    let (text, _, _) = cube(STEEL, PULL);
    let mut bytes = b"\xef\xbb\xbf** Pleuelstange, Werkstoff: St\xe4hl (Latin-1)\n".to_vec();
    bytes.extend_from_slice(text.as_bytes());
    let deck = dir.path().join("cube.inp");
    std::fs::write(&deck, &bytes).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_rodstudy"))
        .arg("solve")
        .arg(&deck)
        .arg("--out")
        .arg(dir.path().join("out"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{stderr}");
    // a closed standard output ends `solve --json` quietly
    let mut child = Command::new(env!("CARGO_BIN_EXE_rodstudy"))
        .arg("solve")
        .arg(&deck)
        .arg("--json")
        .arg("--out")
        .arg(dir.path().join("out"))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let o = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(o.status.code(), Some(0), "{stderr}");
}
