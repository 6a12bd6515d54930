//! `rodstudy solve DECK.inp`: NAFEMS LE10 at two densities against the published σ_yy at D, the
//! same decks through CalculiX (ccx) in the same test, an unknown keyword refused with its line,
//! a patch test (uniform tension of a C3D10 box by *DLOAD pressure), the same for C3D4 with
//! supports on corners only, ccx's step semantics, and what a deck cannot mean refused.
//!
//! NAFEMS, "The Standard NAFEMS Benchmarks", TNSB Rev. 3 (1990), LE10: σ_yy = −5.38 MPa at
//! D = (2, 0, 0.3) m. The decks come from `pipeline/nafems_le10.py` (gmsh, the project's Python
//! environment). CalculiX: `ccx` on PATH, else (as root with apt-get) Debian's `calculix-ccx` is
//! installed, as `tests/browser.rs` installs Chromium; otherwise the test fails and says so.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;
use std::time::Instant;

use rodstudy::deck::{SolveOptions, read_deck_text, solve_model};
use rodstudy::fem::mesh::structured::box_tet10;

const SIGMA_D: f64 = -5.38e6;

fn on_path(name: &str) -> Option<PathBuf> {
    std::env::var_os("PATH").and_then(|paths| {
        std::env::split_paths(&paths)
            .map(|d| d.join(name))
            .find(|p| p.is_file())
    })
}

fn is_root() -> bool {
    std::fs::read_to_string("/proc/self/status")
        .map(|s| {
            s.lines()
                .find_map(|l| l.strip_prefix("Uid:"))
                .and_then(|l| l.split_whitespace().nth(1).map(|u| u == "0"))
                .unwrap_or(false)
        })
        .unwrap_or(false)
}

/// `ccx`, installed with apt-get when missing (as root).
fn ccx() -> &'static Path {
    static CCX: OnceLock<PathBuf> = OnceLock::new();
    CCX.get_or_init(|| {
        if let Some(p) = on_path("ccx") {
            return p;
        }
        assert!(
            is_root() && on_path("apt-get").is_some(),
            "CalculiX `ccx` not found and not root with apt-get: install Debian's calculix-ccx \
             (`sudo apt-get install calculix-ccx`)"
        );
        eprintln!("deck_solve: installing Debian's calculix-ccx …");
        let status = Command::new("sh")
            .args([
                "-c",
                "apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq calculix-ccx",
            ])
            .status()
            .expect("running apt-get");
        assert!(status.success(), "apt-get install calculix-ccx failed");
        on_path("ccx").expect("calculix-ccx installed but ccx is not on PATH")
    })
}

fn work_dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("deck_solve")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn generate_le10(dir: &Path, name: &str, size: f64, size_d: f64) -> PathBuf {
    let python = rodstudy::python_env::python().expect("the project's Python environment");
    let deck = dir.join(format!("{name}.inp"));
    let out = Command::new(python)
        .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("pipeline/nafems_le10.py"))
        .arg(&deck)
        .args(["--size", &size.to_string(), "--size-d", &size_d.to_string()])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "nafems_le10.py: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    deck
}

struct Ours {
    json: serde_json::Value,
    wall_s: f64,
}

fn solve(deck: &Path, out: &Path, extrapolation: &str) -> Ours {
    let t = Instant::now();
    let run = Command::new(env!("CARGO_BIN_EXE_rodstudy"))
        .arg("solve")
        .arg(deck)
        .arg("--out")
        .arg(out)
        .args(["--json", "--extrapolation", extrapolation])
        .output()
        .unwrap();
    let wall_s = t.elapsed().as_secs_f64();
    assert!(
        run.status.success(),
        "rodstudy solve: {}",
        String::from_utf8_lossy(&run.stderr)
    );
    Ours {
        json: serde_json::from_slice(&run.stdout).unwrap(),
        wall_s,
    }
}

struct Ccx {
    /// Displacements of the printed set (from the .dat, 7 digits).
    u: HashMap<i64, [f64; 3]>,
    /// Nodal stresses (from the .frd, 6 digits), ccx order xx yy zz xy yz zx.
    s: HashMap<i64, [f64; 6]>,
    wall_s: f64,
}

fn run_ccx(deck: &Path) -> Ccx {
    let dir = deck.parent().unwrap();
    let job = deck.file_stem().unwrap().to_str().unwrap();
    let t = Instant::now();
    // under a time limit, as the pipeline's children: a ccx that hangs fails the test
    let run = rodstudy::python_env::output_within(
        Command::new(ccx())
            .args(["-i", job])
            .current_dir(dir)
            .env("OMP_NUM_THREADS", "2")
            .env("CCX_NPROC_EQUATION_SOLVER", "2"),
        std::time::Duration::from_secs(300),
    )
    .unwrap_or_else(|e| panic!("ccx on {}: {e}", deck.display()));
    let wall_s = t.elapsed().as_secs_f64();
    assert!(
        run.status.success(),
        "ccx: {}",
        String::from_utf8_lossy(&run.stdout)
    );
    let dat = std::fs::read_to_string(dir.join(format!("{job}.dat"))).unwrap();
    let mut u = HashMap::new();
    let mut in_disp = false;
    for l in dat.lines() {
        let t = l.trim();
        if t.starts_with("displacements") {
            in_disp = true;
            continue;
        }
        if t.is_empty() {
            continue;
        }
        if t.chars().next().is_some_and(|c| c.is_ascii_alphabetic()) {
            in_disp = false;
            continue;
        }
        if in_disp {
            let v: Vec<&str> = t.split_whitespace().collect();
            u.insert(
                v[0].parse().unwrap(),
                [v[1], v[2], v[3]].map(|x| x.parse::<f64>().unwrap()),
            );
        }
    }
    let frd = std::fs::read_to_string(dir.join(format!("{job}.frd"))).unwrap();
    let mut s = HashMap::new();
    let mut block = String::new();
    for l in frd.lines() {
        if let Some(rest) = l.strip_prefix(" -4") {
            block = rest.split_whitespace().next().unwrap_or("").to_string();
        } else if l.starts_with(" -3") {
            block.clear();
        } else if block == "STRESS" && l.starts_with(" -1") {
            let node: i64 = l[3..13].trim().parse().unwrap();
            let v: [f64; 6] =
                std::array::from_fn(|i| l[13 + 12 * i..25 + 12 * i].trim().parse().unwrap());
            s.insert(node, v);
        }
    }
    Ccx { u, s, wall_s }
}

fn set_d(json: &serde_json::Value) -> (i64, [f64; 3], [f64; 6]) {
    let d = &json["node_sets"]["D"];
    let id = d["nodes"][0].as_i64().unwrap();
    let u: [f64; 3] = serde_json::from_value(d["U"][0].clone()).unwrap();
    let s: [f64; 6] = serde_json::from_value(d["S"][0].clone()).unwrap();
    (id, u, s)
}

/// (1) LE10 at two densities, within 1.5 % on the finer; (2) ccx on the same decks: σ_yy at D
/// and the displacements of the printed set to 1e-5 (relative).
#[test]
fn nafems_le10_against_the_target_and_ccx() {
    let dir = work_dir("le10");
    let mut rows = Vec::new();
    for (name, size, size_d) in [("le10_coarse", 0.3, 0.1), ("le10_fine", 0.15, 0.04)] {
        let deck = generate_le10(&dir, name, size, size_d);
        let ours = solve(&deck, &dir.join(format!("{name}_out")), "calculix");
        let exact = solve(&deck, &dir.join(format!("{name}_out_exact")), "exact");
        let ccx = run_ccx(&deck);
        let (id, u, s) = set_d(&ours.json);
        let (_, _, s_exact) = set_d(&exact.json);
        let cu = ccx.u[&id];
        let cs = ccx.s[&id];
        let scale = u.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let du = (0..3).map(|j| (u[j] - cu[j]).abs()).fold(0.0, f64::max) / scale;
        let ds = (s[1] / cs[1] - 1.0).abs();
        let ds_exact = (s_exact[1] / cs[1] - 1.0).abs();
        let err = s[1] / SIGMA_D - 1.0;
        let dofs = ours.json["dofs"].as_u64().unwrap();
        eprintln!(
            "{name}: {dofs} DOF, σ_yy(D) ours {:.5e} (exact extrapolation {:.5e}), ccx {:.5e}, \
             target {SIGMA_D:.3e}, error {:+.2} %; |Δu|/|u| {du:.1e}, Δσ_yy {ds:.1e} \
             (exact table {ds_exact:.1e}); wall ours {:.2} s, ccx {:.2} s",
            s[1],
            s_exact[1],
            cs[1],
            100.0 * err,
            ours.wall_s,
            ccx.wall_s
        );
        assert!(
            du < 1e-5,
            "{name}: displacements at D differ from ccx by {du:.2e}"
        );
        assert!(ds < 1e-5, "{name}: σ_yy at D differs from ccx by {ds:.2e}");
        // the exact extrapolation differs from ccx's 5-decimal table by about 1e-5
        assert!(
            ds_exact < 3e-5,
            "{name}: exact-table σ_yy differs by {ds_exact:.2e}"
        );
        // the pressure load: 1 MPa on the quarter annulus, π/4 (3.25·2.75 − 2·1) m²
        let applied = ours.json["steps"][0]["applied_total"][2].as_f64().unwrap();
        assert!(
            (applied / -5.4487e6 - 1.0).abs() < 1e-3,
            "applied {applied}"
        );
        rows.push((name, err));
    }
    let (_, fine_err) = rows[1];
    assert!(
        fine_err.abs() < 0.015,
        "fine LE10 mesh: σ_yy at D off the target by {:.2} %",
        100.0 * fine_err
    );
}

/// (3) An unknown keyword is refused with its line number.
#[test]
fn unknown_keyword_refused_with_its_line() {
    let deck = "*HEADING\nt\n*NODE\n1, 0, 0, 0\n** comment\n*ORIENTATION, NAME=O\n1,0,0,0,1,0\n";
    let err = read_deck_text(Path::new("bad.inp"), deck)
        .unwrap_err()
        .to_string();
    assert!(err.contains("bad.inp:6:"), "{err}");
    assert!(err.contains("*ORIENTATION"), "{err}");
    // an unsupported parameter and an unsupported *DLOAD label, likewise
    let err = read_deck_text(Path::new("bad.inp"), "*NODE, SYSTEM=C\n1, 0, 0, 0\n")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("bad.inp:1:") && err.contains("SYSTEM"),
        "{err}"
    );
}

/// A C3D10 box deck (nodes 1.., elements 1..) with the x = 0 face on rollers and tension `sigma`
/// on the x = lx face by *DLOAD pressure (or *CLOAD equivalent nodal loads).
fn box_deck(sigma: f64, cload: bool) -> (String, f64) {
    let (lx, ly, lz) = (2.0, 1.0, 0.5);
    let mesh = box_tet10(lx, ly, lz, 4, 3, 2).unwrap();
    let mut s = String::from("*HEADING\npatch test\n*NODE\n");
    for (i, p) in mesh.nodes().iter().enumerate() {
        s += &format!("{}, {:.17e}, {:.17e}, {:.17e}\n", i + 1, p[0], p[1], p[2]);
    }
    s += "*ELEMENT, TYPE=C3D10, ELSET=EALL\n";
    for (e, el) in mesh.elements().iter().enumerate() {
        let ids: Vec<String> = el.iter().map(|n| (n + 1).to_string()).collect();
        s += &format!(
            "{}, {}\n{}\n",
            e + 1,
            ids[..7].join(", "),
            ids[7..].join(", ")
        );
    }
    let near = |a: f64, b: f64| (a - b).abs() < 1e-12;
    let ids = |f: &dyn Fn(&[f64; 3]) -> bool| -> Vec<String> {
        mesh.nodes()
            .iter()
            .enumerate()
            .filter(|(_, p)| f(p))
            .map(|(i, _)| (i + 1).to_string())
            .collect()
    };
    s += "*NSET, NSET=X0\n";
    for c in ids(&|p| near(p[0], 0.0)).chunks(10) {
        s += &(c.join(", ") + "\n");
    }
    s += "*NSET, NSET=XL\n";
    for c in ids(&|p| near(p[0], lx)).chunks(10) {
        s += &(c.join(", ") + "\n");
    }
    let origin = ids(&|p| near(p[0], 0.0) && near(p[1], 0.0) && near(p[2], 0.0));
    let y_end = ids(&|p| near(p[0], 0.0) && near(p[1], ly) && near(p[2], 0.0));
    s += &format!(
        "*NSET, NSET=ORIGIN\n{}\n*NSET, NSET=YEND\n{}\n",
        origin[0], y_end[0]
    );
    s += "*MATERIAL, NAME=STEEL\n*ELASTIC\n210000, 0.3\n*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL\n";
    s += "*BOUNDARY\nX0, 1, 1\nORIGIN, 2, 3\nYEND, 3, 3\n*STEP\n*STATIC\n";
    let faces = rodstudy::fem::boundary::boundary_faces(&mesh).unwrap();
    if cload {
        // equivalent nodal loads of a uniform traction on 6-node faces: 0 at the corners, 1/3 of
        // the face load at each midside node
        let mut f = vec![0.0; mesh.n_nodes()];
        for bf in &faces {
            let x: Vec<[f64; 3]> = bf.nodes.iter().map(|&n| mesh.nodes()[n]).collect();
            if x.iter().all(|p| near(p[0], lx)) {
                let a = 0.5
                    * ((x[1][1] - x[0][1]) * (x[2][2] - x[0][2])
                        - (x[2][1] - x[0][1]) * (x[1][2] - x[0][2]))
                        .abs();
                for &n in &bf.nodes[3..] {
                    f[n] += sigma * a / 3.0;
                }
            }
        }
        s += "*CLOAD\n";
        for (n, v) in f.iter().enumerate() {
            if *v != 0.0 {
                s += &format!("{}, 1, {v:.17e}\n", n + 1);
            }
        }
    } else {
        s += "*DLOAD\n";
        for bf in &faces {
            if bf.nodes.iter().all(|&n| near(mesh.nodes()[n][0], lx)) {
                // rodstudy's local faces are CalculiX's P1..P4 in order
                s += &format!("{}, P{}, {}\n", bf.element + 1, bf.local_face + 1, -sigma);
            }
        }
    }
    s += "*NODE PRINT, NSET=XL, TOTALS=YES\nU, S\n*NODE PRINT, NSET=X0, TOTALS=YES\nRF\n*EL PRINT, ELSET=EALL\nS\n*END STEP\n";
    (s, sigma * ly * lz)
}

/// (4) Patch test: uniform tension of a C3D10 box → uniform σ to 1e-10 at every node and
/// integration point, reactions equal to the load.
#[test]
fn patch_test_uniform_tension() {
    for cload in [false, true] {
        let sigma = 100.0;
        let (text, load) = box_deck(sigma, cload);
        let model = read_deck_text(Path::new("box.inp"), &text).unwrap();
        let sol = solve_model(&model, SolveOptions::default()).unwrap();
        let st = &sol.steps[0];
        for s in &st.s {
            let want = [sigma, 0.0, 0.0, 0.0, 0.0, 0.0];
            for c in 0..6 {
                assert!(
                    (s[c] - want[c]).abs() < 1e-10 * sigma,
                    "cload {cload}: nodal σ {s:?}"
                );
            }
        }
        for el in st.element_sets["EALL"].s.as_ref().unwrap() {
            for ip in el {
                assert!((ip[0] - sigma).abs() < 1e-10 * sigma, "{ip:?}");
                assert!(ip[1..].iter().all(|v| v.abs() < 1e-10 * sigma), "{ip:?}");
            }
        }
        let rx = st.reaction_totals["X0"][0];
        assert!(
            (rx + load).abs() < 1e-10 * load,
            "cload {cload}: reaction {rx}, load {load}"
        );
        assert!((st.applied_total[0] - load).abs() < 1e-10 * load);
        let total = st.node_sets["X0"].rf_total.unwrap();
        assert!((total[0] + load).abs() < 1e-10 * load);
        // u_x = σ x / E along the loaded face
        let xl = &st.node_sets["XL"];
        for u in xl.u.as_ref().unwrap() {
            assert!((u[0] - sigma * 2.0 / 210000.0).abs() < 1e-12);
        }
    }
}

/// The box of [`box_deck`] as C3D4 (its tet10 mesh's corners; the midside nodes stay in *NODE,
/// unused), loaded by `cards` (put after `*STATIC`), with the same supports and output requests.
fn box_c3d4(cards: &str) -> String {
    let (tet10, _) = box_deck(100.0, false);
    let mut s = String::new();
    let mut in_elements = false;
    let mut pending: Vec<String> = Vec::new();
    for line in tet10.lines() {
        if line.starts_with('*') {
            in_elements = line.starts_with("*ELEMENT");
            if line.starts_with("*DLOAD") {
                break;
            }
            s += &line.replace("C3D10", "C3D4");
            s += "\n";
            continue;
        }
        if in_elements {
            // id + 7 nodes, then 3 nodes: keep id and the four corners
            pending.extend(line.split(',').map(|f| f.trim().to_string()));
            if pending.len() == 11 {
                s += &(pending[..5].join(", ") + "\n");
                pending.clear();
            }
        } else {
            s += line;
            s += "\n";
        }
    }
    s + cards
        + "*NODE PRINT, NSET=XL, TOTALS=YES\nU, S\n*NODE PRINT, NSET=X0, TOTALS=YES\nRF\n*EL PRINT, ELSET=EALL\nS\n*END STEP\n"
}

/// The *DLOAD lines of [`box_deck`]: tension `sigma` on the x = lx face.
fn box_tension(sigma: f64) -> String {
    let (tet10, _) = box_deck(sigma, false);
    let from = tet10.find("*DLOAD").unwrap();
    let to = tet10.find("*NODE PRINT").unwrap();
    tet10[from..to].to_string()
}

/// (5) C3D4 is solved as ccx's linear tetrahedron (constant strain, one integration point): the
/// patch test holds with supports on corners only: uniform σ, u = σ L / E, reactions equal to the
/// load.
#[test]
fn a_c3d4_patch_test_holds_with_supports_on_corners_only() {
    let sigma = 100.0;
    let load = sigma * 1.0 * 0.5;
    let text = box_c3d4(&box_tension(sigma));
    let model = read_deck_text(Path::new("box4.inp"), &text).unwrap();
    let st = &solve_model(&model, SolveOptions::default()).unwrap().steps[0];
    for el in st.element_sets["EALL"].s.as_ref().unwrap() {
        for ip in el {
            assert!((ip[0] - sigma).abs() < 1e-9 * sigma, "{ip:?}");
            assert!(ip[1..].iter().all(|v| v.abs() < 1e-9 * sigma), "{ip:?}");
        }
    }
    // the box's unused midside nodes are printed as zeros (as ccx prints nodes of no element)
    let xl = st.node_sets["XL"].u.as_ref().unwrap();
    let used: Vec<_> = xl.iter().filter(|u| u[0] != 0.0).collect();
    assert_eq!(used.len(), 12, "the corners of the loaded face, 4 × 3");
    for u in used {
        assert!((u[0] - sigma * 2.0 / 210000.0).abs() < 1e-12, "{u:?}");
    }
    let rx = st.reaction_totals["X0"][0];
    assert!(
        (rx + load).abs() < 1e-9 * load,
        "reaction {rx}, load {load}"
    );
    let total = st.node_sets["X0"].rf_total.unwrap();
    assert!((total[0] + load).abs() < 1e-9 * load, "{total:?}");
}

/// (6) Step semantics as ccx 2.20 has them: a load given twice within a step adds (two *DLOAD
/// cards, two GRAV lines), given again in a later step it replaces; a step without *NODE PRINT
/// keeps the previous step's requests, and the first one in a step replaces them; two requests on
/// one set print both variables.
#[test]
fn loads_repeated_within_a_step_add_and_output_requests_carry_over() {
    let sigma = 100.0;
    let u_one = sigma * 2.0 / 210000.0;
    let tension = box_tension(sigma);
    let mut text = box_c3d4(&format!("{tension}{tension}"));
    // a second step: the same tension once (replaces the first step's doubled one), no requests
    text += &format!("*STEP\n*STATIC\n{tension}*END STEP\n");
    // a third: gravity along x and along z on the same elements (adds: ρ g V (1, 0, 1); the
    // tension of step 2 carries over), and a second request on XL
    text = text.replace("*SOLID SECTION", "*DENSITY\n7.8e-9\n*SOLID SECTION");
    text += "*STEP\n*STATIC\n*DLOAD\nEALL, GRAV, 9810, 1, 0, 0\nEALL, GRAV, 9810, 0, 0, 1\n*NODE PRINT, NSET=XL\nRF\n*NODE PRINT, NSET=XL\nU\n*END STEP\n";
    let model = read_deck_text(Path::new("steps.inp"), &text).unwrap();
    let sol = solve_model(&model, SolveOptions::default()).unwrap();
    let ux = |k: usize| sol.steps[k].node_sets["XL"].u.as_ref().unwrap()[0][0];
    assert!((ux(0) - 2.0 * u_one).abs() < 1e-12, "step 1: {}", ux(0));
    assert!((ux(1) - u_one).abs() < 1e-12, "step 2: {}", ux(1));
    assert!(
        sol.steps[1].node_sets.contains_key("X0"),
        "step 2 keeps the requests"
    );
    let weight = 7.8e-9 * 9810.0 * 2.0 * 1.0 * 0.5;
    let applied = sol.steps[2].applied_total;
    assert!(
        (applied[0] - weight - sigma * 0.5).abs() < 1e-9 * sigma
            && (applied[2] - weight).abs() < 1e-9 * weight,
        "step 3 applied {applied:?}, gravity ρgV {weight}"
    );
    // step 3's first *NODE PRINT replaces the requests carried over: XL's U and RF, no S, no X0
    let xl = &sol.steps[2].node_sets["XL"];
    assert!(
        xl.u.is_some() && xl.rf.is_some() && xl.s.is_none(),
        "U and RF on XL"
    );
    assert!(!sol.steps[2].node_sets.contains_key("X0"));
}

/// (7) What a deck cannot mean is refused with its line: non-finite numbers, an element turned
/// inside out (named by its id and line, not its position), and supports that leave a rigid-body
/// motion free (a single tet held on one edge turns about it).
#[test]
fn non_finite_numbers_inverted_elements_and_mechanisms_are_refused() {
    let tet = |order: &str, support: &str, load: &str| {
        format!(
            "*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n3, 0.1, 1.3, 0.2\n4, 0.3, 0.2, 1.7\n5, .5, 0, 0\n\
             6, .55, .65, .1\n7, .05, .65, .1\n8, .15, .1, .85\n9, .65, .1, .85\n10, .2, .75, .95\n\
             *ELEMENT, TYPE=C3D10, ELSET=EALL\n57, {order}\n*MATERIAL, NAME=STEEL\n*ELASTIC\n\
             210000, 0.3\n*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL\n*BOUNDARY\n{support}\
             *STEP\n*STATIC\n*CLOAD\n{load}\n*END STEP\n"
        )
    };
    let ok = "1,2,3,4,5,6,7,8,9,10";
    let held = "1,1,3\n2,1,3\n3,1,3\n";
    // the tet itself solves
    let model = read_deck_text(Path::new("t.inp"), &tet(ok, held, "4, 2, 1.")).unwrap();
    assert!(solve_model(&model, SolveOptions::default()).is_ok());
    for bad in ["nan", "inf", "1e400"] {
        let err = read_deck_text(Path::new("t.inp"), &tet(ok, held, &format!("4, 2, {bad}")))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("t.inp:25:") && err.contains("not a finite number"),
            "{bad}: {err}"
        );
    }
    let inverted = "1,3,2,4,7,6,5,8,10,9";
    let model = read_deck_text(Path::new("t.inp"), &tet(inverted, held, "4, 2, 1.")).unwrap();
    let err = solve_model(&model, SolveOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("element 57 (line 13)") && err.contains("inverted"),
        "{err}"
    );
    // held on the edge 1-2 (and its midside node): free to turn about it
    let model = read_deck_text(
        Path::new("t.inp"),
        &tet(ok, "1,1,3\n2,1,3\n5,1,3\n", "4, 2, 1."),
    )
    .unwrap();
    let err = solve_model(&model, SolveOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("rigid-body motion"),
        "a mechanism must be refused: {err}"
    );
}
