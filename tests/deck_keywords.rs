//! `rodstudy solve` on decks written as FreeCAD's FEM workbench and CalculiX users write them, each
//! through CalculiX (`ccx`, Debian's calculix-ccx) in the same test: the keywords beyond the
//! basic subset (*INCLUDE, 2-coordinate node lines, two materials, *SURFACE with *DSLOAD,
//! *DLOAD CENTRIF and GRAV, *BOUNDARY FIXED, *TRANSFORM rectangular and cylindrical,
//! *EQUATION, C3D4 as a linear tet, output E and RF totals, *BUCKLE, *FREQUENCY, FreeCAD's
//! *PHYSICAL CONSTANTS / *OUTPUT / *STEP INC= cards). Agreement: every node's displacement to
//! 1e-5 of the largest, the reaction totals to 1e-5 of the applied load, nodal strains to 1e-5 of
//! the largest, buckling factors and eigenvalues to 1e-5 (relative). The reference is ccx on the
//! same files: a second program, whose numbers rodstudy must reproduce.

use std::path::{Path, PathBuf};

#[path = "common/ccx.rs"]
mod ccx;
use ccx::{Ccx, max_abs, run_ccx, solve};

use rodstudy::fem::mesh::structured::box_tet10;

fn work_dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("deck_keywords")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A 2 × 1 × 0.5 box of C3D10 (4 × 3 × 2 cells, 6 tets each), in FreeCAD's style: the nodes in an
/// included file (those at z = 0 as `id, x, y`), the elements in two materials by x (steel
/// x < 1, aluminium x > 1), node sets X0 (x = 0) and XL (x = 2), element-face surface FXL on
/// x = 2. `linear`: C3D4 on the corners.
fn box_model(dir: &Path, linear: bool) -> String {
    let mesh = box_tet10(2.0, 1.0, 0.5, 4, 3, 2).unwrap();
    let mut nodes = String::from(
        "** nodes written apart, as FreeCAD's split input writes them\n*Node, NSET=Nall\n",
    );
    for (i, p) in mesh.nodes().iter().enumerate() {
        if p[2] == 0.0 {
            nodes += &format!("{}, {}, {}\n", i + 1, p[0], p[1]);
        } else {
            nodes += &format!("{}, {}, {}, {}\n", i + 1, p[0], p[1], p[2]);
        }
    }
    std::fs::write(dir.join("nodes.inp"), nodes).unwrap();
    let mut s = String::from(
        "** written in the style of FreeCAD's inp writer for CalculiX\n*INCLUDE,INPUT=nodes.inp\n",
    );
    let (ty, n) = if linear { ("C3D4", 4) } else { ("C3D10", 10) };
    let mut left = Vec::new();
    let mut right = Vec::new();
    s += &format!("*Element, TYPE={ty}, ELSET=Evolumes\n");
    for (e, el) in mesh.elements().iter().enumerate() {
        let ids: Vec<String> = el[..n].iter().map(|k| (k + 1).to_string()).collect();
        s += &format!("{}, {}\n", e + 1, ids.join(", "));
        let cx: f64 = el[..4].iter().map(|&k| mesh.nodes()[k][0]).sum::<f64>() / 4.0;
        if cx < 1.0 { &mut left } else { &mut right }.push((e + 1).to_string());
    }
    let set = |name: &str, ids: &[String]| {
        let mut t = format!("*ELSET,ELSET={name}\n");
        for c in ids.chunks(8) {
            t += &(c.join(",") + ",\n");
        }
        t
    };
    s += &set("SolidMaterialSolid", &left);
    s += &set("SolidMaterial001Solid", &right);
    let nset = |name: &str, f: &dyn Fn(&[f64; 3]) -> bool| {
        let mut t = format!("*NSET,NSET={name}\n");
        for (i, p) in mesh.nodes().iter().enumerate() {
            let corner = i < mesh.n_nodes()
                && (!linear || mesh.elements().iter().any(|el| el[..4].contains(&i)));
            if f(p) && corner {
                t += &format!("{},\n", i + 1);
            }
        }
        t
    };
    s += &nset("X0", &|p| p[0] == 0.0);
    s += &nset("XL", &|p| (p[0] - 2.0).abs() < 1e-12);
    // the faces on x = 2: the face k whose three corners lie there
    s += "*SURFACE, NAME=FXL, TYPE=ELEMENT\n";
    for (e, el) in mesh.elements().iter().enumerate() {
        for (k, f) in [[0, 1, 2], [0, 1, 3], [1, 2, 3], [0, 2, 3]]
            .iter()
            .enumerate()
        {
            if f.iter()
                .all(|&c| (mesh.nodes()[el[c]][0] - 2.0).abs() < 1e-12)
            {
                s += &format!("{}, S{}\n", e + 1, k + 1);
            }
        }
    }
    s += "** Physical constants for SI(mm) unit system with Kelvins\n*PHYSICAL CONSTANTS, ABSOLUTE ZERO=0, STEFAN BOLTZMANN=5.670374419e-11\n";
    s += "*MATERIAL, NAME=SolidMaterial\n*ELASTIC\n210000,0.3\n*DENSITY\n7.9e-09\n*EXPANSION, ZERO=0\n0\n";
    s += "*MATERIAL, NAME=SolidMaterial001\n*ELASTIC\n70000,0.33\n*DENSITY\n2.7e-09\n";
    s += "*SOLID SECTION, ELSET=SolidMaterialSolid, MATERIAL=SolidMaterial\n";
    s += "*SOLID SECTION, ELSET=SolidMaterial001Solid, MATERIAL=SolidMaterial001\n";
    s
}

/// FreeCAD's output cards, with every node's U printed for the comparison.
const OUTPUTS: &str = "*NODE FILE\nU\n*EL FILE\nS, E\n*NODE PRINT, NSET=Nall\nU\n*NODE PRINT, NSET=X0, TOTALS=ONLY\nRF\n\n*OUTPUT, FREQUENCY=1\n*END STEP\n";

/// Every node's U against ccx's, relative to the largest |U|; returns the difference.
fn compare_u(ours: &serde_json::Value, ccx: &Ccx) -> f64 {
    let set = &ours["node_sets"]["NALL"];
    let ids: Vec<i64> = serde_json::from_value(set["nodes"].clone()).unwrap();
    let u: Vec<[f64; 3]> = serde_json::from_value(set["U"].clone()).unwrap();
    let scale = max_abs(ccx.u.values().flatten());
    assert!(scale > 0.0);
    let mut d = 0.0f64;
    for (id, ui) in ids.iter().zip(&u) {
        let c = ccx.u[id];
        for j in 0..3 {
            d = d.max((ui[j] - c[j]).abs() / scale);
        }
    }
    d
}

/// The strains of every node against ccx's frd TOSTRAIN (its order xx yy zz xy yz zx).
fn compare_e(dir: &Path, stem: &str, ours: &serde_json::Value, ccx: &Ccx) -> f64 {
    let _ = (dir, stem);
    let set = &ours["node_sets"]["NALL"];
    let ids: Vec<i64> = serde_json::from_value(set["nodes"].clone()).unwrap();
    let e: Vec<[f64; 6]> = serde_json::from_value(set["E"].clone()).unwrap();
    let theirs = &ccx.frd["TOSTRAIN"];
    let scale = max_abs(theirs.values().flatten());
    let mut d = 0.0f64;
    for (id, ei) in ids.iter().zip(&e) {
        let Some(c) = theirs.get(id) else { continue };
        // ours [xx yy zz xy xz yz], ccx's frd [xx yy zz xy yz zx]
        let o = [ei[0], ei[1], ei[2], ei[3], ei[5], ei[4]];
        for j in 0..6 {
            d = d.max((o[j] - c[j]).abs() / scale);
        }
    }
    d
}

fn run_both(dir: &Path, name: &str, text: &str) -> (serde_json::Value, Ccx) {
    let deck = dir.join(format!("{name}.inp"));
    std::fs::write(&deck, text).unwrap();
    (solve(&deck), run_ccx(&deck))
}

/// A FreeCAD-style static deck with two materials, *INCLUDE, 2-coordinate nodes, *BOUNDARY FIXED,
/// *SURFACE + *DSLOAD tension, CENTRIF and GRAV: U, E and the RF total against ccx.
#[test]
fn freecad_static_with_surfaces_centrif_and_two_materials_matches_ccx() {
    for linear in [false, true] {
        let name = if linear {
            "static_c3d4"
        } else {
            "static_c3d10"
        };
        let dir = work_dir(name);
        let mut s = box_model(&dir, linear);
        s += "*STEP, INC=2000\n*STATIC\n*BOUNDARY, FIXED\nX0,1,3\n";
        s += "*DSLOAD\nFXL, P, -10.0\n*DLOAD\nEvolumes, CENTRIF, 1.0e6, 0.0, 0.5, 0.25, 1.0, 0.0, 0.0\nEvolumes, GRAV, 9810, 0, 0, -1\n";
        s += &OUTPUTS.replace("*NODE PRINT, NSET=Nall\nU", "*NODE PRINT, NSET=Nall\nU, E");
        let (ours, ccx) = run_both(&dir, name, &s);
        let du = compare_u(&ours, &ccx);
        let de = compare_e(&dir, name, &ours, &ccx);
        let rf: [f64; 3] =
            serde_json::from_value(ours["node_sets"]["X0"]["RF_total"].clone()).unwrap();
        let crf = ccx.totals["X0"];
        let applied: [f64; 3] =
            serde_json::from_value(ours["steps"][0]["applied_total"].clone()).unwrap();
        let scale = max_abs(applied.iter());
        let drf = (0..3)
            .map(|j| (rf[j] - crf[j]).abs() / scale)
            .fold(0.0, f64::max);
        eprintln!(
            "{name}: |ΔU|/max|U| {du:.1e}, |ΔE|/max|E| {de:.1e}, |ΔRF_total|/|f| {drf:.1e} (RF {rf:?}, ccx {crf:?})"
        );
        assert!(du < 1e-5 && de < 1e-5 && drf < 1e-5, "{name}");
        assert!(
            ours["warnings"]
                .as_array()
                .unwrap()
                .iter()
                .any(|w| w.as_str().unwrap().contains("*EXPANSION"))
        );
    }
}

/// *TRANSFORM (cylindrical about an axis along x: the tangential DOF held on the loaded end;
/// rectangular on the supported end: the supports in axes turned 30° about z) and *EQUATION
/// (two corners of the free end tied in z), a radial *CLOAD in local axes: U and RF total against
/// ccx.
#[test]
fn transforms_and_equations_match_ccx() {
    let dir = work_dir("transform");
    let mesh = box_tet10(2.0, 1.0, 0.5, 4, 3, 2).unwrap();
    let find = |p: [f64; 3]| {
        1 + mesh
            .nodes()
            .iter()
            .position(|q| (0..3).all(|j| (q[j] - p[j]).abs() < 1e-12))
            .unwrap()
    };
    let (a, b, c) = (
        find([2.0, 0.0, 0.5]),
        find([2.0, 1.0, 0.5]),
        find([2.0, 1.0, 0.0]),
    );
    let mut s = box_model(&dir, false);
    let (c30, s30) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
    s += &format!(
        "*TRANSFORM, NSET=X0, TYPE=R\n{c30},{s30},0,{},{c30},0\n",
        -s30
    );
    s += "*TRANSFORM, NSET=XL, TYPE=C\n0,0.55,0.3,1,0.55,0.3\n";
    s += &format!("*EQUATION\n2\n{a},3,1.0,{b},3,-1.0\n");
    s += "*STEP\n*STATIC\n*BOUNDARY\nX0,1,3\nXL,2,2\n";
    s += &format!("*CLOAD\n{c},1,100.0\n{a},3,-50.0\n*DSLOAD\nFXL, P, -10.0\n");
    // ccx prints a transformed node's values in its local axes unless GLOBAL=YES
    s += &OUTPUTS
        .replace("NSET=Nall\nU", "NSET=Nall, GLOBAL=YES\nU")
        .replace("NSET=X0, TOTALS=ONLY", "NSET=X0, TOTALS=ONLY, GLOBAL=YES");
    let (ours, ccx) = run_both(&dir, "transform", &s);
    let du = compare_u(&ours, &ccx);
    let rf: [f64; 3] = serde_json::from_value(ours["node_sets"]["X0"]["RF_total"].clone()).unwrap();
    let crf = ccx.totals["X0"];
    let scale = max_abs(crf.iter());
    let drf = (0..3)
        .map(|j| (rf[j] - crf[j]).abs() / scale)
        .fold(0.0, f64::max);
    eprintln!(
        "transform/equation: |ΔU|/max|U| {du:.1e}, |ΔRF_total| {drf:.1e} (RF {rf:?}, ccx {crf:?})"
    );
    assert!(du < 1e-5 && drf < 1e-5);
}

/// *BUCKLE under end compression and *FREQUENCY (FreeCAD's `10,0.01,1000000.0` form, here 4
/// modes): the factors and eigenvalues ω² against ccx's.
#[test]
fn buckle_and_frequency_steps_match_ccx() {
    let dir = work_dir("eigen");
    let mut s = box_model(&dir, false);
    s += "*STEP\n*BUCKLE\n3\n*BOUNDARY\nX0,1,3\n*DSLOAD\nFXL, P, 100.0\n*NODE FILE\nU\n*END STEP\n";
    let (ours, ccx) = run_both(&dir, "buckle", &s);
    let factors: Vec<f64> =
        serde_json::from_value(ours["steps"][0]["eigen"]["buckling_factors"].clone()).unwrap();
    assert_eq!(factors.len(), 3);
    assert_eq!(
        ccx.buckling.len(),
        3,
        "ccx's buckling factors read from its .dat"
    );
    let d = factors
        .iter()
        .zip(&ccx.buckling)
        .map(|(a, b)| (a / b - 1.0).abs())
        .fold(0.0, f64::max);
    eprintln!(
        "*BUCKLE: ours {factors:?}, ccx {:?}: max rel. diff {d:.1e}",
        ccx.buckling
    );
    assert!(d < 1e-5);

    let mut s = box_model(&dir, false);
    s += "*STEP\n*FREQUENCY\n4,0.01,1000000.0\n*BOUNDARY\nX0,1,3\n*NODE FILE\nU\n*EL FILE\nS, E\n*END STEP\n";
    let (ours, ccx) = run_both(&dir, "frequency", &s);
    let eig: Vec<f64> =
        serde_json::from_value(ours["steps"][0]["eigen"]["eigenvalues"].clone()).unwrap();
    assert_eq!(eig.len(), 4);
    assert_eq!(ccx.eigen.len(), 4, "ccx's eigenvalues read from its .dat");
    let d = eig
        .iter()
        .zip(&ccx.eigen)
        .map(|(a, b)| (a / b - 1.0).abs())
        .fold(0.0, f64::max);
    eprintln!(
        "*FREQUENCY: ours {eig:?}, ccx {:?}: max rel. diff {d:.1e}",
        ccx.eigen
    );
    assert!(d < 1e-5);
}

/// What stays unsupported is refused, every line at once, each with its file and line.
#[test]
fn unsupported_cards_are_all_refused_with_their_lines() {
    let deck = "*NODE\n1, 0, 0, 0\n*ELEMENT, TYPE=C3D20, ELSET=E\n1, 1\n*CONTACT PAIR, INTERACTION=I\nA, B\n*STEP, NLGEOM\n*STATIC\n*COUPLING, REF NODE=1, SURFACE=S, CONSTRAINT NAME=C\n*END STEP\n";
    let err = rodstudy::deck::read_deck_text(Path::new("bad.inp"), deck)
        .unwrap_err()
        .to_string();
    for (line, what) in [
        (3, "C3D20"),
        (5, "NODE TO SURFACE"),
        (7, "NLGEOM"),
        (9, "COUPLING"),
    ] {
        assert!(
            err.contains(&format!("bad.inp:{line}:")) && err.contains(what),
            "{line} {what}: {err}"
        );
    }
}
