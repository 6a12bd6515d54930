//! Stage 1 end to end on files: each STL defect named with the file, ASCII and binary forms of
//! one mesh agreeing, the mechanism-frame figures and the bore check, against the voxel rod's
//! independent reference (a sum over its cells).

use nalgebra::{Matrix3, Vector3};
use rodstudy::geometry::design::mass_of_design;
use rodstudy::geometry::primitives::{
    ascii_stl, binary_stl, flipped, to_soup, transformed, voxel_rod,
};
use std::path::{Path, PathBuf};

/// The voxel rod in millimetres (as CAD exports it), pins at (0,0,0) and (180,0,0) mm.
fn rod_mm() -> rodstudy::geometry::IndexedMesh {
    voxel_rod().0.scaled(1000.0)
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

fn error_of(path: &Path) -> String {
    format!("{:#}", mass_of_design(path).unwrap_err())
}

/// Reference figures of the voxel rod, computed from its cells (not from its surface).
fn cell_reference() -> (f64, Vector3<f64>, Matrix3<f64>) {
    let (_, centres, h) = voxel_rod();
    let m_cell = 7800.0 * h.powi(3);
    let g = centres.iter().sum::<Vector3<f64>>() / centres.len() as f64;
    let mut inertia = Matrix3::zeros();
    for c in &centres {
        let d = c - g;
        inertia += Matrix3::identity() * (m_cell * h * h / 6.0)
            + (Matrix3::identity() * d.norm_squared() - d * d.transpose()) * m_cell;
    }
    (m_cell * centres.len() as f64, g, inertia)
}

#[test]
fn rod_in_millimetres_gives_si_figures_in_the_mechanism_frame() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(dir.path(), "voxel.stl", &binary_stl(&to_soup(&rod_mm())));
    let d = mass_of_design(&path).unwrap();
    let (mass, g, inertia) = cell_reference();
    let rel = |a: f64, b: f64| (a - b).abs() / b.abs();
    assert!(rel(d.mass_kg, mass) < 1e-9, "{} vs {mass}", d.mass_kg);
    assert!((d.l1_m - g.x).abs() < 1e-9);
    assert!(d.offset_m.abs() < 1e-9 && d.offset_z_m.abs() < 1e-9);
    assert!(rel(d.i_zz_kgm2, inertia[(2, 2)]) < 1e-8);
    assert!(rel(d.i_xx_kgm2, inertia[(0, 0)]) < 1e-8);
    // The square bores: 40 mm and 20 mm across, so the nearest wall is 20 mm and 10 mm away.
    assert!((d.crank_bore_radius_m - 0.020).abs() < 1e-9);
    assert!((d.piston_bore_radius_m - 0.010).abs() < 1e-9);
    assert!((d.centre_distance_m - 0.18).abs() < 1e-12);
    assert_eq!(d.design, "voxel");
    assert!(d.warnings.is_empty());
}

#[test]
fn ascii_and_binary_forms_of_one_mesh_agree_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let soup = to_soup(&rod_mm());
    let bin = mass_of_design(&write(dir.path(), "b.stl", &binary_stl(&soup))).unwrap();
    let asc = mass_of_design(&write(
        dir.path(),
        "a.stl",
        ascii_stl("rod", &soup).as_bytes(),
    ))
    .unwrap();
    assert_eq!(asc.format, "ascii");
    assert_eq!(bin.format, "binary");
    assert_eq!(asc.mass_kg, bin.mass_kg);
    assert_eq!(
        asc.inertia_about_centroid_kgm2,
        bin.inertia_about_centroid_kgm2
    );
    // A binary file whose header begins with "solid", as some CAD systems write it.
    let mut solid_header = binary_stl(&soup);
    solid_header[..22].copy_from_slice(b"solid part exported by");
    let sh = mass_of_design(&write(dir.path(), "s.stl", &solid_header)).unwrap();
    assert_eq!(sh.mass_kg, bin.mass_kg);
}

#[test]
fn rotated_rod_with_matching_sidecar_gives_the_same_frame_figures() {
    let dir = tempfile::tempdir().unwrap();
    let rotation = *nalgebra::Rotation3::from_euler_angles(0.4, 0.2, -0.7).matrix();
    let shift = Vector3::new(250.0, -120.0, 40.0);
    let mesh = transformed(&rod_mm(), &rotation, shift);
    let path = write(dir.path(), "turned.stl", &binary_stl(&to_soup(&mesh)));
    let a = rotation * Vector3::zeros() + shift;
    let b = rotation * Vector3::new(180.0, 0.0, 0.0) + shift;
    let axis = rotation * Vector3::z();
    let sidecar = format!(
        "name = \"Turned rod\"\ncrank_pin = [{}, {}, {}]\npiston_pin = [{}, {}, {}]\npin_axis = [{}, {}, {}]\n",
        a.x, a.y, a.z, b.x, b.y, b.z, axis.x, axis.y, axis.z
    );
    write(dir.path(), "turned.toml", sidecar.as_bytes());
    let d = mass_of_design(&path).unwrap();
    let (mass, g, inertia) = cell_reference();
    assert_eq!(d.design, "Turned rod");
    // Single-precision storage of the turned coordinates limits agreement to ~1e-6.
    assert!((d.mass_kg - mass).abs() < 1e-5 * mass);
    assert!((d.l1_m - g.x).abs() < 1e-6);
    assert!(d.offset_m.abs() < 1e-6);
    assert!((d.i_zz_kgm2 - inertia[(2, 2)]).abs() < 1e-5 * inertia[(2, 2)]);
    assert!((d.i_xx_kgm2 - inertia[(0, 0)]).abs() < 1e-5 * inertia[(0, 0)]);
}

#[test]
fn inverted_file_is_flipped_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(
        dir.path(),
        "inv.stl",
        &binary_stl(&to_soup(&flipped(&rod_mm()))),
    );
    let d = mass_of_design(&path).unwrap();
    assert!(d.mass_kg > 0.0);
    assert!(
        d.warnings.iter().any(|w| w.contains("flipped")),
        "{:?}",
        d.warnings
    );
}

#[test]
fn every_defect_names_the_file_and_the_defect() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let good = binary_stl(&to_soup(&rod_mm()));
    let mut open = rod_mm();
    open.triangles.truncate(open.triangles.len() - 1);
    let mut nan = good.clone();
    nan[84 + 12..84 + 16].copy_from_slice(&f32::NAN.to_le_bytes());
    let ascii_nan = "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex nan 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid x\n";
    let mut two = rod_mm();
    let far = transformed(
        &rod_mm(),
        &Matrix3::identity(),
        Vector3::new(0.0, 500.0, 0.0),
    );
    let n = two.vertices.len() as u32;
    two.vertices.extend(&far.vertices);
    // the second body inside out: two bodies are one bonded body (a warning), but not when
    // one of them faces inward
    two.triangles.extend(
        far.triangles
            .iter()
            .map(|&[a, b, c]| [c, b, a].map(|i| i + n)),
    );
    let mut one_flipped = rod_mm();
    one_flipped.triangles[10].swap(1, 2);
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        ("empty.stl", vec![], "empty file"),
        (
            "text.stl",
            b"Not a mesh at all, just some words in a file named .stl.".repeat(3),
            "not an STL",
        ),
        (
            "truncated.stl",
            good[..good.len() - 75].to_vec(),
            "truncated binary STL",
        ),
        ("nan.stl", nan, "non-finite coordinate"),
        ("ascii_nan.stl", ascii_nan.as_bytes().to_vec(), "got NaN"),
        (
            "open.stl",
            binary_stl(&to_soup(&open)),
            "open mesh: 3 boundary edge(s)",
        ),
        ("two.stl", binary_stl(&to_soup(&two)), "2 separate shells"),
        (
            "flipped_one.stl",
            binary_stl(&to_soup(&one_flipped)),
            "inconsistently oriented",
        ),
    ];
    for (name, bytes, defect) in cases {
        let path = write(d, name, &bytes);
        let e = error_of(&path);
        assert!(
            e.contains(name),
            "{name}: message does not name the file: {e}"
        );
        assert!(e.contains(defect), "{name}: expected «{defect}» in: {e}");
    }
}

#[test]
fn units_and_pin_mistakes_are_explained() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Exported in metres but read as the default millimetres.
    let metres = write(d, "metres.stl", &binary_stl(&to_soup(&voxel_rod().0)));
    let e = error_of(&metres);
    assert!(e.contains("metres.stl") && e.contains("units"), "{e}");
    // Saying so in the sidecar fixes it.
    write(d, "metres.toml", b"units = \"m\"\n");
    let ok = mass_of_design(&metres).unwrap();
    assert!((ok.crank_bore_radius_m - 0.02).abs() < 1e-9);
    // A piston pin placed in the shank (in material).
    let rod = write(d, "pins.stl", &binary_stl(&to_soup(&rod_mm())));
    write(d, "pins.toml", b"piston_pin = [100.0, 0.0, 0.0]\n");
    let e = error_of(&rod);
    assert!(
        e.contains("piston pin (B)") && e.contains("inside material"),
        "{e}"
    );
    // A crank pin beside the rod (in air, outside the part's bounding box).
    write(
        d,
        "pins.toml",
        b"crank_pin = [0.0, 300.0, 0.0]\npiston_pin = [180.0, 300.0, 0.0]\n",
    );
    let e = error_of(&rod);
    assert!(
        e.contains("crank pin (A) at (0.000, 300.000, 0.000) mm lies outside the part"),
        "{e}"
    );
    // In air within the bounding box, beside the shank: not in a bore.
    write(
        d,
        "pins.toml",
        b"crank_pin = [100.0, 30.0, 0.0]\npiston_pin = [180.0, 0.0, 0.0]\n",
    );
    let e = error_of(&rod);
    assert!(
        e.contains("crank pin (A)") && e.contains("not inside a bore"),
        "{e}"
    );
    // A crank pin 5 mm off the centre of design 1's Ø50 big-end bore: a wall all round it, so
    // only the bore's own axis shows the mistake.
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let off = d.join("off.stl");
    std::fs::copy(root.join("designs/design1.stl"), &off).unwrap();
    write(
        d,
        "off.toml",
        b"crank_pin = [5.0, 0.0, 0.0]\npiston_pin = [180.0, 0.0, 0.0]\n",
    );
    let e = error_of(&off);
    assert!(
        e.contains("crank pin (A) is 5.000 mm off the axis of the bore around it")
            && e.contains("radius 25.000 mm"),
        "{e}"
    );
    // 0.3 mm off (1.2 % of the radius, a rounded coordinate): studied, with a warning
    write(
        d,
        "off.toml",
        b"crank_pin = [0.3, 0.0, 0.0]\npiston_pin = [180.0, 0.0, 0.0]\n",
    );
    let near = mass_of_design(&off).unwrap();
    assert!(
        near.warnings
            .iter()
            .any(|w| w.contains("crank pin (A) is 0.300 mm off the axis")),
        "{:?}",
        near.warnings
    );
    // A sidecar with a typo.
    write(d, "pins.toml", b"densty = 7000.0\n");
    let e = error_of(&rod);
    assert!(
        e.contains("pins.toml") && e.contains("unknown field `densty`"),
        "{e}"
    );
}

#[test]
fn implausible_mass_is_warned_about() {
    let dir = tempfile::tempdir().unwrap();
    // The rod at 1/50 scale in mm: 1.8 g at steel density.
    let path = write(
        dir.path(),
        "tiny.stl",
        &binary_stl(&to_soup(&rod_mm().scaled(0.02))),
    );
    write(dir.path(), "tiny.toml", b"piston_pin = [3.6, 0.0, 0.0]\n");
    let d = mass_of_design(&path).unwrap();
    assert!(
        d.warnings.iter().any(|w| w.contains("implausible")),
        "{:?}",
        d.warnings
    );
    // the rod in metres read as millimetres, 1e-9 of its mass: not a rod in any units
    let path = write(
        dir.path(),
        "metres.stl",
        &binary_stl(&to_soup(&rod_mm().scaled(1e-3))),
    );
    write(
        dir.path(),
        "metres.toml",
        b"piston_pin = [0.18, 0.0, 0.0]\n",
    );
    let e = format!("{:#}", mass_of_design(&path).unwrap_err());
    assert!(
        e.contains("metres.stl")
            && e.contains("cannot be a connecting rod's")
            && e.contains("`density`"),
        "{e}"
    );
}

/// Sidecar values that disagree with the geometry: a `pin_axis` 16.7° off the bores of design 1
/// (they run along z) is refused with the angle (atan 0.3 = 16.70°); pins swapped (A in the
/// small-end bore) are studied with a warning that says so; four coordinates are refused.
#[test]
fn sidecar_values_that_disagree_with_the_bores() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let rod = d.join("rod.stl");
    std::fs::copy(root.join("designs/design1.stl"), &rod).unwrap();
    write(
        d,
        "rod.toml",
        b"crank_pin = [0.0, 0.0, 0.0]\npiston_pin = [180.0, 0.0, 0.0]\npin_axis = [0, 0.3, 1]\n",
    );
    let e = error_of(&rod);
    assert!(
        e.contains("`pin_axis`") && e.contains("16.7° off the axis of the bore"),
        "{e}"
    );
    write(
        d,
        "rod.toml",
        b"crank_pin = [180.0, 0.0, 0.0]\npiston_pin = [0.0, 0.0, 0.0]\npin_axis = \"z\"\n",
    );
    let m = mass_of_design(&rod).unwrap();
    assert!(
        m.warnings.iter().any(|w| w.contains("pins are swapped")),
        "{:?}",
        m.warnings
    );
    write(d, "rod.toml", b"crank_pin = [0, 0, 0, 99]\n");
    let e = error_of(&rod);
    assert!(
        e.contains("rod.toml") && e.contains("`crank_pin` must have 3 coordinates"),
        "{e}"
    );
}

/// A sidecar saved with a byte-order mark and a Latin-1 comment (é as the byte 0xE9) is read: its
/// `density` is what counts.
#[test]
fn a_sidecar_with_a_bom_and_a_latin1_comment_is_read() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let rod = d.join("rod.stl");
    std::fs::copy(root.join("designs/design1.stl"), &rod).unwrap();
    let mut text = b"\xEF\xBB\xBF# acier tremp\xE9\ndensity = 7850.0\n".to_vec();
    text.extend_from_slice(b"crank_pin = [0.0, 0.0, 0.0]\npiston_pin = [180.0, 0.0, 0.0]\n");
    write(d, "rod.toml", &text);
    let m = mass_of_design(&rod).unwrap_or_else(|e| panic!("{e:#}"));
    assert_eq!(m.density_kg_m3, 7850.0);
}
