//! Contact decks (`*SURFACE INTERACTION`, `*SURFACE BEHAVIOR`, `*CONTACT PAIR, TYPE=SURFACE TO
//! SURFACE`), each through CalculiX (`ccx` 2.20) in the same test and against a closed form.
//!
//! Two C3D10 blocks of steel stacked in z, both 1 × 1 × 0.5, meshed differently (3 × 3 and 5 × 5
//! cells in plan: the contact faces do not match), on rollers (x = 0, y = 0, z = 0), the top face
//! pushed down by δ, an initial gap g₀ between the blocks. The blocks are in uniaxial stress, so
//! the contact pressure is uniform and known: p = (δ − g₀) / (H/E + 1/K) for the linear law p =
//! K · overclosure (H = 1 the two blocks' height), p = (δ − g₀) E / H for hard contact. And a
//! punch: a 0.5 × 0.5 block pressed into the middle of a clamped 1 × 1 block, where the pressure
//! peaks at the punch's edges.
//!
//! Tolerances (measured 2026-11-29) and their source: on the stacked blocks the linear law gives
//! the closed form's force to 2e-7 and ccx's displacements to 2.2e-4 of the largest (ccx's
//! face-to-face contact integrates the same law; the difference is the integration of the
//! master's shape functions across its face edges inside a slave face, which rodstudy does on
//! 4² pieces of each sub-triangle). HARD is solved exactly by rodstudy and as a linear penalty
//! K = 50 E by ccx, so there the two differ by ccx's overclosure p/K (1/51 of δ − g₀ here). On
//! the punch the two discretisations of the pressure's edge peak differ: total force by 1.6e-3,
//! displacements by 1.2e-2 of the largest.

use std::path::{Path, PathBuf};

#[path = "common/ccx.rs"]
mod ccx;
use ccx::{Ccx, max_abs, run_ccx, solve};

use rodstudy::fem::mesh::structured::box_tet10;

const E: f64 = 210000.0;

fn work_dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("deck_contact")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The two blocks' deck up to the step: `behavior` the *SURFACE BEHAVIOR card with its line,
/// `punch` the smaller upper block. Sets: NALL, X0, Y0, Z0, ZTOP; surfaces SLAVE (the upper
/// block's bottom) and MASTER (the lower block's top).
fn blocks(gap: f64, behavior: &str, punch: bool) -> String {
    let lower = box_tet10(1.0, 1.0, 0.5, 5, 5, 2).unwrap();
    let (w, x0) = if punch { (0.5, 0.25) } else { (1.0, 0.0) };
    let upper = box_tet10(w, w, 0.5, 3, 3, 2).unwrap();
    let mut nodes: Vec<[f64; 3]> = lower.nodes().to_vec();
    let off = nodes.len();
    nodes.extend(
        upper
            .nodes()
            .iter()
            .map(|p| [p[0] + x0, p[1] + x0, p[2] + 0.5 + gap]),
    );
    let mut elements: Vec<(Vec<usize>, bool)> = lower
        .elements()
        .iter()
        .map(|e| (e.to_vec(), false))
        .collect();
    elements.extend(
        upper
            .elements()
            .iter()
            .map(|e| (e.iter().map(|k| k + off).collect(), true)),
    );
    let mut s = String::from("*NODE, NSET=NALL\n");
    for (i, p) in nodes.iter().enumerate() {
        s += &format!("{}, {:?}, {:?}, {:?}\n", i + 1, p[0], p[1], p[2]);
    }
    s += "*ELEMENT, TYPE=C3D10, ELSET=EALL\n";
    for (k, (e, _)) in elements.iter().enumerate() {
        let ids: Vec<String> = e.iter().map(|n| (n + 1).to_string()).collect();
        s += &format!("{}, {}\n", k + 1, ids.join(", "));
    }
    let ztop = 1.0 + gap;
    let nset = |name: &str, f: &dyn Fn(&[f64; 3]) -> bool| {
        let mut t = format!("*NSET, NSET={name}\n");
        for (i, p) in nodes.iter().enumerate() {
            if f(p) {
                t += &format!("{},\n", i + 1);
            }
        }
        t
    };
    s += &nset("X0", &|p| p[0].abs() < 1e-12);
    s += &nset("Y0", &|p| p[1].abs() < 1e-12);
    s += &nset("Z0", &|p| p[2].abs() < 1e-12);
    s += &nset("ZTOP", &|p| (p[2] - ztop).abs() < 1e-12);
    let surface = |name: &str, upper: bool, z: f64| {
        let mut t = format!("*SURFACE, NAME={name}, TYPE=ELEMENT\n");
        for (k, (e, up)) in elements.iter().enumerate() {
            if *up != upper {
                continue;
            }
            for (f, c) in [[0, 1, 2], [0, 1, 3], [1, 2, 3], [0, 2, 3]]
                .iter()
                .enumerate()
            {
                if c.iter().all(|&i| (nodes[e[i]][2] - z).abs() < 1e-12) {
                    t += &format!("{}, S{}\n", k + 1, f + 1);
                }
            }
        }
        t
    };
    s += &surface("SLAVE", true, 0.5 + gap);
    s += &surface("MASTER", false, 0.5);
    s += &format!("*MATERIAL, NAME=STEEL\n*ELASTIC\n{E}, 0.3\n");
    s += "*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL\n*SURFACE INTERACTION, NAME=SI\n";
    s += behavior;
    s += "*CONTACT PAIR, INTERACTION=SI, TYPE=SURFACE TO SURFACE\nSLAVE, MASTER\n";
    s
}

fn step(delta: f64, punch: bool) -> String {
    let supports = if punch {
        "Z0, 1, 3\nZTOP, 1, 2\n"
    } else {
        "X0, 1, 1\nY0, 2, 2\nZ0, 3, 3\n"
    };
    format!(
        "*STEP\n*STATIC\n*BOUNDARY\n{supports}ZTOP, 3, 3, {}\n*NODE PRINT, NSET=NALL\nU\n\
         *NODE PRINT, NSET=Z0, TOTALS=ONLY\nRF\n*NODE FILE\nU\n*EL FILE\nS\n\
         *CONTACT FILE\nCSTR\n*END STEP\n",
        -delta
    )
}

fn run_both(name: &str, text: &str) -> (serde_json::Value, Ccx) {
    let dir = work_dir(name);
    let deck = dir.join(format!("{name}.inp"));
    std::fs::write(&deck, text).unwrap();
    (solve(&deck), run_ccx(&deck))
}

/// Every node's U against ccx's, relative to ccx's largest.
fn compare_u(ours: &serde_json::Value, ccx: &Ccx) -> f64 {
    let set = &ours["steps"][0]["node_sets"]["NALL"];
    let ids: Vec<i64> = serde_json::from_value(set["nodes"].clone()).unwrap();
    let u: Vec<[f64; 3]> = serde_json::from_value(set["U"].clone()).unwrap();
    let scale = max_abs(ccx.u.values().flatten());
    let mut d = 0.0f64;
    for (id, ui) in ids.iter().zip(&u) {
        for (a, b) in ui.iter().zip(&ccx.u[id]) {
            d = d.max((a - b).abs() / scale);
        }
    }
    d
}

fn contact(ours: &serde_json::Value) -> (f64, Vec<f64>) {
    let c = &ours["steps"][0]["contact"];
    (
        c["normal_force"].as_f64().unwrap(),
        serde_json::from_value(c["pressure"].clone()).unwrap(),
    )
}

fn z_reaction(ours: &serde_json::Value) -> f64 {
    ours["steps"][0]["node_sets"]["Z0"]["RF_total"][2]
        .as_f64()
        .unwrap()
}

/// The linear law across a closing gap: the uniform pressure of the closed form at every slave
/// node, the force through the lower block's support, and ccx's displacements.
#[test]
fn stacked_blocks_with_a_linear_law_match_the_closed_form_and_ccx() {
    let (k, gap, delta) = (1.0e7, 2.0e-4, 1.0e-3);
    let s = blocks(
        gap,
        &format!("*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR\n{k}\n"),
        false,
    ) + &step(delta, false);
    let (ours, ccx) = run_both("linear", &s);
    let exact = (delta - gap) / (1.0 / E + 1.0 / k);
    let (force, pressure) = contact(&ours);
    let spread = pressure
        .iter()
        .map(|p| (p - exact).abs() / exact)
        .fold(0.0, f64::max);
    let du = compare_u(&ours, &ccx);
    let ccx_force = ccx.totals["Z0"][2];
    eprintln!(
        "linear: force {force} (closed form {exact}, ccx {ccx_force}), pressures within \
         {spread:.1e} of it, |ΔU|/max|U| {du:.1e}"
    );
    assert!((force - exact).abs() < 1e-5 * exact);
    assert!((z_reaction(&ours) - exact).abs() < 1e-5 * exact);
    assert!((ccx_force - exact).abs() < 1e-5 * exact, "ccx itself");
    assert!(spread < 5e-3);
    assert!(du < 1e-3);
}

/// HARD contact: rodstudy's exact solution against the closed form; ccx's penalty (K = 50 E, its
/// default) against its own closed form; the two differ by ccx's overclosure.
#[test]
fn stacked_blocks_with_hard_contact_match_the_closed_form_and_ccx_to_its_penalty() {
    let (gap, delta) = (2.0e-4, 1.0e-3);
    let s =
        blocks(gap, "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=HARD\n", false) + &step(delta, false);
    let (ours, ccx) = run_both("hard", &s);
    let exact = (delta - gap) * E;
    let penalty = (delta - gap) / (1.0 / E + 1.0 / (50.0 * E));
    let (force, pressure) = contact(&ours);
    let du = compare_u(&ours, &ccx);
    let ccx_force = ccx.totals["Z0"][2];
    eprintln!(
        "hard: force {force} (closed form {exact}); ccx {ccx_force} (its penalty's closed form \
         {penalty}); |ΔU|/max|U| {du:.1e}"
    );
    assert!((force - exact).abs() < 1e-5 * exact);
    assert!(pressure.iter().all(|p| (p - exact).abs() < 5e-3 * exact));
    assert!((ccx_force - penalty).abs() < 1e-5 * penalty);
    // ccx's overclosure p/K is 1/51 of the closure δ − g₀: the displacements differ by about
    // that share of it
    assert!(du < 2e-2);
    assert!(
        ours["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .any(|w| w.as_str().unwrap().contains("HARD solved as hard contact"))
    );
}

/// A punch: the contact pressure peaks at the punch's edges; rodstudy and ccx agree on the force
/// and the displacements to their discretisations' difference there.
#[test]
fn a_punch_matches_ccx_to_the_discretisation_of_its_edge_peak() {
    let s = blocks(
        0.0,
        "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR\n1e7\n",
        true,
    ) + &step(1.0e-3, true);
    let (ours, ccx) = run_both("punch", &s);
    let (force, pressure) = contact(&ours);
    let ccx_force = ccx.totals["Z0"][2];
    let du = compare_u(&ours, &ccx);
    let (lo, hi) = pressure
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), p| (a.min(*p), b.max(*p)));
    eprintln!("punch: force {force} (ccx {ccx_force}), pressure {lo} … {hi}, |ΔU|/max|U| {du:.1e}");
    assert!((force - ccx_force).abs() < 3e-3 * ccx_force);
    assert!(du < 2e-2);
    assert!(
        lo >= 0.0 && hi > 1.5 * force / 0.25,
        "an edge peak above the mean pressure"
    );
}

/// What stays refused, with its line: friction, node-to-surface contact, other laws, contact in
/// a buckling step.
#[test]
fn contact_refusals_name_their_line() {
    let dir = work_dir("refusals");
    let linear = "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR\n1e7\n";
    let cases: [(String, &str); 4] = [
        (
            blocks(0.0, &format!("{linear}*FRICTION\n0.2, 1e5\n"), false) + &step(1e-3, false),
            "*FRICTION is not supported",
        ),
        (
            blocks(0.0, linear, false).replace("TYPE=SURFACE TO SURFACE", "TYPE=NODE TO SURFACE")
                + &step(1e-3, false),
            "TYPE=NODE TO SURFACE",
        ),
        (
            blocks(
                0.0,
                "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=EXPONENTIAL\n1e-3, 10\n",
                false,
            ) + &step(1e-3, false),
            "EXPONENTIAL is not supported",
        ),
        (
            blocks(0.0, linear, false) + &step(1e-3, false).replace("*STATIC", "*BUCKLE\n2"),
            "*BUCKLE or *FREQUENCY step",
        ),
    ];
    for (k, (text, what)) in cases.iter().enumerate() {
        let deck = dir.join(format!("refused{k}.inp"));
        std::fs::write(&deck, text).unwrap();
        let run = std::process::Command::new(env!("CARGO_BIN_EXE_rodstudy"))
            .arg("solve")
            .arg(&deck)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&run.stderr);
        assert!(!run.status.success(), "case {k} accepted");
        assert!(
            err.contains(what) && (err.contains(&format!("refused{k}.inp:")) || k == 3),
            "case {k}: wanted '{what}' in: {err}"
        );
    }
}
