//! Helpers shared by the end-to-end tests: copying a design, the one crank–slider rig built
//! directly on the multibody core, a small C3D10 deck and a STEP box.
// each test binary uses only some of them
#![allow(dead_code)]

use nalgebra::{SVector, Vector2};
use rodstudy::mechanism::{
    BodyId, CrankMotion, CrankSliderLinkage, LinkageJoint, MultibodyBuilder, MultibodySystem,
};
use std::path::Path;

/// Copies design `stem` (its STL and sidecar) from folder `from` into folder `to`.
pub fn copy_design(from: &Path, to: &Path, stem: &str) {
    for ext in ["stl", "toml"] {
        std::fs::copy(
            from.join(format!("{stem}.{ext}")),
            to.join(format!("{stem}.{ext}")),
        )
        .unwrap();
    }
}

/// A crank–slider built directly on the core ([`CrankSliderLinkage`], so that
/// l <= r is possible): crank 8 kg, rod 3 kg, piston 5 kg, crank and rod
/// centroids at mid-length, optional duplicate pin at O instead of the slide,
/// optional slide line y = slide_y, driven by `motion`, with gravity.
pub fn raw_crank_slider(
    r: f64,
    l: f64,
    motion: CrankMotion,
    duplicate_pin: bool,
    slide_y: f64,
) -> MultibodySystem<9> {
    let linkage = CrankSliderLinkage {
        crank_radius_m: r,
        centre_distance_m: l,
        crank_centroid_m: r / 2.0,
        rod_l1_m: l / 2.0,
        rod_offset_m: 0.0,
        slide_y_m: slide_y,
        masses_kg: [8.0, 3.0, 5.0],
        inertias_kgm2: [0.015, 0.02, 0.0],
    };
    let mut b = MultibodyBuilder::new();
    linkage.add_bodies(&mut b);
    linkage.add_joint(&mut b, LinkageJoint::O, "O");
    if duplicate_pin {
        linkage.add_joint(&mut b, LinkageJoint::O, "O duplicate");
    }
    linkage.add_joint(&mut b, LinkageJoint::A, "A");
    linkage.add_joint(&mut b, LinkageJoint::B, "B");
    if !duplicate_pin {
        linkage.add_joint(&mut b, LinkageJoint::Slide, "slide");
    }
    b.add_driving(
        "crank drive",
        BodyId::Ground,
        CrankSliderLinkage::CRANK,
        motion,
    )
    .gravity(Vector2::new(0.0, -9.81));
    b.build::<9>().expect("nine equations for nine coordinates")
}

/// Assembly guess for [`raw_crank_slider`] at φ = 0: everything laid along +x.
pub fn guess(r: f64, l: f64) -> SVector<f64, 9> {
    SVector::<f64, 9>::from_column_slice(&[
        r / 2.0,
        0.0,
        0.0,
        r + l / 2.0,
        0.0,
        0.0,
        r + l,
        0.0,
        0.0,
    ])
}

/// A C3D10 cube deck (1 m, 2 × 1 × 1 hexahedra of six tets): the x = 0 face fixed, `material`
/// after `*MATERIAL`, `load` after `*STATIC`. Returns the text and the line of each marker:
/// (`*ELASTIC` data, first element line).
pub fn cube_deck(material: &str, load: &str) -> (String, usize, usize) {
    let mesh = rodstudy::fem::mesh::structured::box_tet10(1.0, 1.0, 1.0, 2, 1, 1).unwrap();
    let mut s = String::from("*HEADING\ncube\n*NODE, NSET=ALL\n");
    for (i, p) in mesh.nodes().iter().enumerate() {
        s += &format!("{}, {:?}, {:?}, {:?}\n", i + 1, p[0], p[1], p[2]);
    }
    s += "*ELEMENT, TYPE=C3D10, ELSET=EALL\n";
    let first_element = s.lines().count() + 1;
    for (e, el) in mesh.elements().iter().enumerate() {
        let ids: Vec<String> = el.iter().map(|n| (n + 1).to_string()).collect();
        s += &format!("{}, {}\n", e + 1, ids.join(", "));
    }
    s += "*NSET, NSET=X0\n";
    let x0: Vec<String> = (0..mesh.n_nodes())
        .filter(|&n| mesh.nodes()[n][0] == 0.0)
        .map(|n| (n + 1).to_string())
        .collect();
    s += &(x0.join(", ") + "\n");
    s += "*MATERIAL, NAME=STEEL\n";
    let elastic = s.lines().count() + 2;
    s += material;
    s += "*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL\n*BOUNDARY\nX0, 1, 3\n*STEP\n*STATIC\n";
    s += load;
    s += "*NODE PRINT, NSET=ALL\nU\n*END STEP\n";
    (s, elastic, first_element)
}

/// A box 100 × 40 × 20 mm written by gmsh (OpenCASCADE) as STEP, as text (the file in `dir` is
/// removed again).
pub fn box_step(dir: &Path) -> String {
    let path = dir.join("box.step");
    let script = format!(
        "import gmsh\ngmsh.initialize(readConfigFiles=False)\ngmsh.option.setNumber('General.Verbosity', 1)\n\
         gmsh.model.occ.addBox(0, 0, 0, 100, 40, 20)\ngmsh.model.occ.synchronize()\n\
         gmsh.write({:?})\ngmsh.finalize()\n",
        path.to_str().unwrap()
    );
    let o = std::process::Command::new(rodstudy::python_env::python().unwrap())
        .args(["-c", &script])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&path).unwrap();
    std::fs::remove_file(&path).unwrap();
    text
}
