//! `*COUPLING` with `*KINEMATIC` and `*DISTRIBUTING`: a 100 × 20 × 10 mm bar of C3D10 (FreeCAD's
//! mesh, `tests/data/freecad/static_bore_tet10.inp`) fixed at x = 0 and loaded through the 12 mm
//! bore at x = 85 by a reference node on the bore's axis, as ccx users load a bore. Each deck
//! runs through CalculiX (`ccx`) in the same test; agreement: every node's displacement to 1e-5
//! of the largest, every node's stress to 1e-5 of the largest, the reaction total at the
//! support to 1e-5 of the load. Refusals name their line.

use std::path::{Path, PathBuf};

#[path = "common/ccx.rs"]
mod ccx;
use ccx::{Ccx, max_abs, run_ccx, solve};

fn work_dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("deck_coupling")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

const REF: i64 = 9001;

/// The bar's nodes, elements, the fixed face's node set, its material and section, a reference
/// node REF on the bore axis at mid-thickness (node set REF), and the bore's element faces as
/// surface BORE.
fn bar_with_bore() -> String {
    let src = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/freecad/static_bore_tet10.inp"),
    )
    .unwrap();
    let lines: Vec<&str> = src.lines().collect();
    let end = lines
        .iter()
        .position(|l| l.starts_with("** constraints displacement node sets"))
        .unwrap();
    let mat = lines
        .iter()
        .position(|l| l.starts_with("*MATERIAL"))
        .unwrap();
    let sec = lines
        .iter()
        .position(|l| l.starts_with("*SOLID SECTION"))
        .unwrap();
    // nodes and elements, for the bore's faces
    let mut nodes = std::collections::HashMap::new();
    let mut elements = Vec::new();
    let mut mode = "";
    for l in &lines[..end] {
        if l.starts_with("*Node") {
            mode = "n";
        } else if l.starts_with("*Element") {
            mode = "e";
        } else if l.starts_with('*') {
            mode = "";
        } else if !l.trim().is_empty() {
            let f: Vec<&str> = l
                .split(',')
                .map(str::trim)
                .filter(|s| !s.is_empty())
                .collect();
            match mode {
                "n" => {
                    let x: Vec<f64> = f[1..].iter().map(|v| v.parse().unwrap()).collect();
                    nodes.insert(f[0].parse::<i64>().unwrap(), x);
                }
                "e" => elements.push(
                    f.iter()
                        .map(|v| v.parse::<i64>().unwrap())
                        .collect::<Vec<_>>(),
                ),
                _ => {}
            }
        }
    }
    let on_bore = |n: i64| {
        let x = &nodes[&n];
        ((x[0] - 85.0).hypot(x[1] - 10.0) - 6.0).abs() < 1e-3
    };
    let mut s = lines[..end].join("\n");
    s += &format!("\n*NODE, NSET=REF\n{REF}, 85, 10, 5\n*SURFACE, NAME=BORE, TYPE=ELEMENT\n");
    let mut faces = 0;
    for el in &elements {
        for (k, f) in [[0, 1, 2], [0, 1, 3], [1, 2, 3], [0, 2, 3]]
            .iter()
            .enumerate()
        {
            if f.iter().all(|&c| on_bore(el[1 + c])) {
                s += &format!("{}, S{}\n", el[0], k + 1);
                faces += 1;
            }
        }
    }
    assert!(faces > 50, "the bore's faces: {faces}");
    s += &lines[mat..=sec].join("\n");
    s + "\n"
}

const OUTPUTS: &str = "*NODE PRINT, NSET=Nall\nU, S\n*NODE PRINT, NSET=REF\nU\n\
    *NODE PRINT, NSET=ConstraintFixed, TOTALS=ONLY\nRF\n*NODE FILE\nU\n*EL FILE\nS\n*END STEP\n";

fn run_both(name: &str, text: &str) -> (serde_json::Value, Ccx) {
    let dir = work_dir(name);
    let deck = dir.join(format!("{name}.inp"));
    std::fs::write(&deck, text).unwrap();
    (solve(&deck), run_ccx(&deck))
}

/// Largest differences: U and S over every node of the bar (relative to ccx's largest), the
/// reaction total at the fixed face (relative to the applied force `load`).
fn compare(ours: &serde_json::Value, ccx: &Ccx, load: f64) -> (f64, f64, f64) {
    let set = &ours["steps"][0]["node_sets"]["NALL"];
    let ids: Vec<i64> = serde_json::from_value(set["nodes"].clone()).unwrap();
    let u: Vec<[f64; 3]> = serde_json::from_value(set["U"].clone()).unwrap();
    let s: Vec<[f64; 6]> = serde_json::from_value(set["S"].clone()).unwrap();
    let uscale = max_abs(ccx.u.values().flatten());
    let stress = &ccx.frd["STRESS"];
    let sscale = max_abs(stress.values().flatten());
    assert!(uscale > 0.0 && sscale > 0.0);
    let (mut du, mut ds) = (0.0f64, 0.0f64);
    for ((id, ui), si) in ids.iter().zip(&u).zip(&s) {
        let c = ccx.u[id];
        for j in 0..3 {
            du = du.max((ui[j] - c[j]).abs() / uscale);
        }
        // ours [xx yy zz xy xz yz], ccx's frd [xx yy zz xy yz zx]
        let o = [si[0], si[1], si[2], si[3], si[5], si[4]];
        let c = &stress[id];
        for j in 0..6 {
            ds = ds.max((o[j] - c[j]).abs() / sscale);
        }
    }
    let rf: [f64; 3] = serde_json::from_value(
        ours["steps"][0]["node_sets"]["CONSTRAINTFIXED"]["RF_total"].clone(),
    )
    .unwrap();
    let crf = ccx.totals["CONSTRAINTFIXED"];
    let drf = (0..3)
        .map(|j| (rf[j] - crf[j]).abs() / load)
        .fold(0.0, f64::max);
    (du, ds, drf)
}

fn reference_u(ours: &serde_json::Value) -> [f64; 3] {
    serde_json::from_value(ours["steps"][0]["node_sets"]["REF"]["U"][0].clone()).unwrap()
}

/// *KINEMATIC on DOFs 1-3: the bore moves rigidly with the reference node, which carries two
/// forces and two moments. U, S, RF total and the reference node's own displacement against ccx.
#[test]
fn kinematic_coupling_through_a_bore_matches_ccx() {
    let mut s = bar_with_bore();
    s += "*COUPLING, REF NODE=9001, SURFACE=BORE, CONSTRAINT NAME=PIN\n*KINEMATIC\n1, 3\n";
    s += "*STEP\n*STATIC\n*BOUNDARY\nConstraintFixed, 1, 3, 0\n";
    s += "*CLOAD\n9001, 1, 500.\n9001, 2, -1000.\n9001, 4, 3000.\n9001, 6, 20000.\n";
    s += OUTPUTS;
    let (ours, ccx) = run_both("kinematic", &s);
    let (du, ds, drf) = compare(&ours, &ccx, 1000.0);
    let r = reference_u(&ours);
    let cr = ccx.u[&REF];
    let dr = (0..3).map(|j| (r[j] - cr[j]).abs()).fold(0.0, f64::max)
        / max_abs(ccx.u.values().flatten());
    eprintln!(
        "kinematic: |ΔU|/max|U| {du:.1e}, |ΔS|/max|S| {ds:.1e}, |ΔRF|/|F| {drf:.1e}, reference \
         node {dr:.1e} (ours {r:?}, ccx {cr:?})"
    );
    assert!(du < 1e-5 && ds < 1e-5 && drf < 1e-5 && dr < 1e-5);
    assert!(r[1] < 0.0, "the reference node follows its load");
}

/// *KINEMATIC on DOFs 1-2 only (the bore free to slide along z), the reference node's rotations
/// about x and y held (*BOUNDARY 4-5), a force and a torque about z.
#[test]
fn kinematic_coupling_with_held_rotations_matches_ccx() {
    let mut s = bar_with_bore();
    s += "*COUPLING, REFNODE=9001, SURFACE=BORE, CONSTRAINTNAME=PIN\n*KINEMATIC\n1, 2\n";
    s += "*STEP\n*STATIC\n*BOUNDARY\nConstraintFixed, 1, 3, 0\n9001, 4, 5\n";
    s += "*CLOAD\n9001, 2, 800.\n9001, 6, -15000.\n";
    s += OUTPUTS;
    let (ours, ccx) = run_both("kinematic_12", &s);
    let (du, ds, drf) = compare(&ours, &ccx, 800.0);
    eprintln!("kinematic 1-2: |ΔU|/max|U| {du:.1e}, |ΔS|/max|S| {ds:.1e}, |ΔRF|/|F| {drf:.1e}");
    assert!(du < 1e-5 && ds < 1e-5 && drf < 1e-5);
}

/// *DISTRIBUTING with the moments (DOFs 1-6): the reference node's forces and moments spread
/// over the bore's nodes by area. U, S and RF total against ccx; the reference node carries
/// nothing itself (U = 0, as ccx prints it).
#[test]
fn distributing_coupling_through_a_bore_matches_ccx() {
    let mut s = bar_with_bore();
    s += "*COUPLING, REF NODE=9001, SURFACE=BORE, CONSTRAINT NAME=PIN\n*DISTRIBUTING\n1, 6\n";
    s += "*STEP\n*STATIC\n*BOUNDARY\nConstraintFixed, 1, 3, 0\n";
    s += "*CLOAD\n9001, 1, 500.\n9001, 2, -1000.\n9001, 3, 200.\n9001, 4, 3000.\n9001, 6, 20000.\n";
    s += OUTPUTS;
    let (ours, ccx) = run_both("distributing", &s);
    let (du, ds, drf) = compare(&ours, &ccx, 1000.0);
    eprintln!("distributing: |ΔU|/max|U| {du:.1e}, |ΔS|/max|S| {ds:.1e}, |ΔRF|/|F| {drf:.1e}");
    assert!(du < 1e-5 && ds < 1e-5 && drf < 1e-5);
    assert_eq!(reference_u(&ours), [0.0; 3]);
    assert_eq!(ccx.u[&REF], [0.0; 3]);
    // the load reaches the support whole: Σ RF = −F
    let rf: [f64; 3] = serde_json::from_value(
        ours["steps"][0]["node_sets"]["CONSTRAINTFIXED"]["RF_total"].clone(),
    )
    .unwrap();
    for (j, f) in [500.0, -1000.0, 200.0].iter().enumerate() {
        assert!((rf[j] + f).abs() < 1e-6 * 1000.0, "{rf:?}");
    }
}

/// What stays refused, each with its line: a node surface under *DISTRIBUTING, a moment not
/// listed under *DISTRIBUTING, a support on a distributing reference node, a moment on a node of
/// no coupling, *COUPLING not followed by its kind, ORIENTATION.
#[test]
fn coupling_refusals_name_their_line() {
    let base = bar_with_bore();
    let at = base.lines().count();
    let dir = work_dir("refusals");
    let cases: [(&str, usize, &str); 6] = [
        (
            "*SURFACE, NAME=BN, TYPE=NODE\nREF\n*COUPLING, REF NODE=9001, SURFACE=BN\n*DISTRIBUTING\n1, 3\n",
            3,
            "element-face surface",
        ),
        (
            "*COUPLING, REF NODE=9001, SURFACE=BORE\n*DISTRIBUTING\n1, 3\n*STEP\n*STATIC\n*CLOAD\n9001, 5, 1.\n*END STEP\n",
            7,
            "moment",
        ),
        (
            "*COUPLING, REF NODE=9001, SURFACE=BORE\n*DISTRIBUTING\n*STEP\n*STATIC\n*BOUNDARY\n9001, 1, 3\n*END STEP\n",
            6,
            "DISTRIBUTING coupling's reference node",
        ),
        (
            "*STEP\n*STATIC\n*CLOAD\n1, 4, 1.\n*END STEP\n",
            4,
            "moments act only",
        ),
        (
            "*COUPLING, REF NODE=9001, SURFACE=BORE\n*STEP\n*STATIC\n*END STEP\n",
            1,
            "followed at once",
        ),
        (
            "*COUPLING, REF NODE=9001, SURFACE=BORE, ORIENTATION=OR1\n*KINEMATIC\n1, 3\n",
            1,
            "ORIENTATION",
        ),
    ];
    for (k, (tail, line, what)) in cases.iter().enumerate() {
        let deck = dir.join(format!("refused{k}.inp"));
        std::fs::write(&deck, format!("{base}{tail}")).unwrap();
        let run = std::process::Command::new(env!("CARGO_BIN_EXE_rodstudy"))
            .arg("solve")
            .arg(&deck)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&run.stderr);
        assert!(!run.status.success(), "case {k} accepted");
        let expect = format!("refused{k}.inp:{}", at + line);
        assert!(
            err.contains(&expect) && err.contains(what),
            "case {k}: wanted '{expect}' and '{what}' in: {err}"
        );
    }
}
