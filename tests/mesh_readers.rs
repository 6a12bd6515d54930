//! The native readers of user volume meshes (gmsh MSH 4.1 ASCII and binary, Abaqus/CalculiX
//! `.inp`) against the meshio path (`pipeline/mesh_rod.py convert`) on meshes made by the
//! project's own gmsh pipeline: the same nodes bit for bit, the same connectivity; malformed files
//! refused naming the file and the line; and `fem --mesh` giving the same numbers either way.
//! Needs the pipeline's Python environment (gmsh, meshio).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use rodstudy::fem::TetMesh;
use rodstudy::mesher::{
    MESH_READER_VAR, MeshRequest, VolumeReader, mesh_stl, mesh_stl_with, read_rodmesh,
    read_volume_mesh_meshio, read_volume_mesh_native, volume_reader,
};

fn python() -> PathBuf {
    rodstudy::python_env::python().expect("the pipeline's Python environment")
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Writes, from gmsh's ASCII MSH 4.1 `msh`: the same mesh as binary MSH 4.1 (gmsh), as `.inp`
/// with C3D10 (meshio's writer), and its corner tetrahedra as linear C3D4 `.inp` and linear MSH
/// 4.1 (meshio's writers).
const CONVERT: &str = r#"
import sys, gmsh, meshio
msh, out = sys.argv[1], sys.argv[2]
gmsh.initialize(readConfigFiles=False)
gmsh.option.setNumber("General.Terminal", 0)
gmsh.open(msh)
gmsh.option.setNumber("Mesh.Binary", 1)
gmsh.write(out + "/binary.msh")
gmsh.finalize()
m = meshio.read(msh)
t10 = m.get_cells_type("tetra10")
meshio.write_points_cells(out + "/quadratic.inp", m.points, [("tetra10", t10)])
meshio.write_points_cells(out + "/linear.inp", m.points, [("tetra", t10[:, :4])])
meshio.write_points_cells(out + "/linear.msh", m.points, [("tetra", t10[:, :4])],
                          file_format="gmsh", binary=False)
"#;

/// design 1 meshed at 8 mm by the pipeline (in the design's units and pose), and its conversions;
/// made once per test binary.
fn meshes() -> &'static Path {
    static DIR: OnceLock<tempfile::TempDir> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let py = python();
        let meshed = mesh_stl(
            &py,
            &root().join("pipeline/mesh_rod.py"),
            &root().join("designs/design1.stl"),
            8.0,
            dir.path(),
        )
        .unwrap();
        assert_eq!(meshed.report.msh, dir.path().join("design1.msh"));
        let out = Command::new(&py)
            .args(["-c", CONVERT])
            .arg(&meshed.report.msh)
            .arg(dir.path())
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        dir
    })
    .path()
}

fn assert_identical(a: &TetMesh, b: &TetMesh, what: &str) {
    assert_eq!(a.n_nodes(), b.n_nodes(), "{what}: node count");
    assert_eq!(a.elements(), b.elements(), "{what}: connectivity");
    for (i, (p, q)) in a.nodes().iter().zip(b.nodes()).enumerate() {
        assert_eq!(
            p.map(f64::to_bits),
            q.map(f64::to_bits),
            "{what}: node {i}: {p:?} vs {q:?}"
        );
    }
}

#[test]
fn native_readers_give_the_meshio_mesh_bit_for_bit() {
    let dir = meshes();
    let work = tempfile::tempdir().unwrap();
    for (name, reader) in [
        ("design1.msh", VolumeReader::GmshMsh41),
        ("binary.msh", VolumeReader::GmshMsh41),
        ("quadratic.inp", VolumeReader::AbaqusInp),
        ("linear.inp", VolumeReader::AbaqusInp),
        ("linear.msh", VolumeReader::GmshMsh41),
    ] {
        let path = dir.join(name);
        assert_eq!(volume_reader(&path).unwrap(), reader, "{name}");
        let native = read_volume_mesh_native(&path, "mm").unwrap();
        let meshio = read_volume_mesh_meshio(&path, "mm", work.path()).unwrap();
        assert_identical(&native, &meshio, name);
        // metres: the numbers as they are
        let m = read_volume_mesh_native(&path, "m").unwrap();
        for (p, q) in m.nodes().iter().zip(native.nodes()) {
            assert_eq!(p.map(|v| (v * 1e-3).to_bits()), q.map(f64::to_bits));
        }
        eprintln!(
            "{name}: {} nodes, {} tet10, identical",
            native.n_nodes(),
            native.n_elements()
        );
    }
    // the four files of the quadratic mesh are one mesh
    let a = read_volume_mesh_native(&dir.join("design1.msh"), "mm").unwrap();
    let b = read_volume_mesh_native(&dir.join("binary.msh"), "mm").unwrap();
    let c = read_volume_mesh_native(&dir.join("quadratic.inp"), "mm").unwrap();
    assert_identical(&a, &b, "ascii vs binary");
    assert_identical(&a, &c, "msh vs inp");
}

/// The adaptive loop's hand-off (`--no-rodmesh`): the mesher writes no `.rodmesh` and the `.msh`
/// is read natively, giving the mesh of the `.rodmesh` route bit for bit (the same STL and size
/// mesh the same; reference: the `.rodmesh` meshio wrote in `meshes()`).
#[test]
fn the_mesher_hands_over_the_msh_natively_without_a_rodmesh() {
    let dir = tempfile::tempdir().unwrap();
    let meshed = mesh_stl_with(
        &python(),
        &root().join("pipeline/mesh_rod.py"),
        &root().join("designs/design1.stl"),
        &MeshRequest {
            size_mm: 8.0,
            native_read: true,
            ..MeshRequest::default()
        },
        dir.path(),
    )
    .unwrap();
    assert_eq!(meshed.report.rodmesh, None);
    assert!(!dir.path().join("design1.rodmesh").exists());
    let reference = read_rodmesh(&meshes().join("design1.rodmesh")).unwrap();
    assert_identical(&meshed.mesh, &reference, "native hand-off");
    assert_eq!(meshed.report.nodes, reference.n_nodes());
}

/// A two-element .inp (the corner tetrahedron of a unit cube and its neighbour), elements
/// continued over two lines, comments, ignored keywords.
fn small_inp() -> String {
    let corners = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 1.0, 1.0],
    ];
    let tets = [[0, 1, 2, 3], [1, 2, 3, 4]];
    let edges = [(0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3)];
    let mut nodes: Vec<[f64; 3]> = corners.to_vec();
    let mut els = Vec::new();
    for t in tets {
        let mut el: Vec<usize> = t.to_vec();
        for (a, b) in edges {
            let (p, q) = (corners[t[a]], corners[t[b]]);
            let m = [
                0.5 * (p[0] + q[0]),
                0.5 * (p[1] + q[1]),
                0.5 * (p[2] + q[2]),
            ];
            let i = nodes.iter().position(|n| *n == m).unwrap_or_else(|| {
                nodes.push(m);
                nodes.len() - 1
            });
            el.push(i);
        }
        els.push(el);
    }
    let mut s = String::from("*HEADING\nsmall test deck\n** a comment\n*NODE, NSET=NALL\n");
    for (i, p) in nodes.iter().enumerate() {
        s += &format!("{}, {:?}, {:?}, {:?}\n", i + 1, p[0], p[1], p[2]);
    }
    s += "*ELEMENT, TYPE=C3D10, ELSET=EALL\n";
    for (e, el) in els.iter().enumerate() {
        let ids: Vec<String> = el.iter().map(|n| (n + 1).to_string()).collect();
        s += &format!(
            "{}, {},\n{}\n",
            e + 1,
            ids[..6].join(", "),
            ids[6..].join(", ")
        );
    }
    s += "*NSET, NSET=FIXED\n1, 2, 3\n*MATERIAL, NAME=STEEL\n*ELASTIC\n210000, 0.3\n";
    s
}

#[test]
fn a_small_deck_reads_natively_as_meshio_reads_it() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("small.inp");
    std::fs::write(&path, small_inp()).unwrap();
    let native = read_volume_mesh_native(&path, "mm").unwrap();
    assert_eq!(native.n_elements(), 2);
    let meshio = read_volume_mesh_meshio(&path, "mm", dir.path()).unwrap();
    assert_identical(&native, &meshio, "small.inp");
}

/// The error of reading `text` as `name`, which must name the file and `line`.
fn refused(name: &str, text: &[u8], line: usize, what: &str) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, text).unwrap();
    let err = read_volume_mesh_native(&path, "mm")
        .expect_err(name)
        .to_string();
    // a defect of the whole file (line 0) is named by the file alone
    let at = if line > 0 {
        format!("{}:{line}:", path.display())
    } else {
        format!("{}:", path.display())
    };
    assert!(err.starts_with(&at), "{name}: expected '{at}…', got: {err}");
    assert!(err.contains(what), "{name}: expected '{what}' in: {err}");
}

#[test]
fn malformed_inp_files_are_refused_with_file_and_line() {
    let good = small_inp();
    let lines: Vec<&str> = good.lines().collect();
    let with = |n: usize, replacement: &str| {
        let mut l = lines.clone();
        l[n - 1] = replacement;
        l.join("\n") + "\n"
    };
    // line 5 is node 1, line 20 the first element's first line (14 nodes)
    assert!(lines[4].starts_with("1, "));
    assert!(lines[19].starts_with("1, "), "{}", lines[19]);
    refused(
        "coord.inp",
        with(5, "1, 0.0, zero, 0.0").as_bytes(),
        5,
        "bad coordinate 'zero'",
    );
    refused(
        "two.inp",
        with(5, "1, 0.0, 0.0").as_bytes(),
        5,
        "found 3 fields",
    );
    refused(
        "dup.inp",
        with(6, "1, 1.0, 0.0, 0.0").as_bytes(),
        6,
        "node 1 defined twice",
    );
    refused(
        "undef.inp",
        with(20, "1, 1, 2, 3, 4, 99, 7,").as_bytes(),
        20,
        "undefined node 99",
    );
    refused(
        "hex.inp",
        with(19, "*ELEMENT, TYPE=C3D8, ELSET=EALL").as_bytes(),
        19,
        "element type C3D8",
    );
    refused(
        "include.inp",
        with(3, "*INCLUDE, INPUT=more.inp").as_bytes(),
        3,
        "*INCLUDE",
    );
    refused(
        "system.inp",
        with(4, "*NODE, SYSTEM=C").as_bytes(),
        4,
        "SYSTEM",
    );
    refused(
        "early.inp",
        "*ELEMENT, TYPE=C3D10\n1, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10\n".as_bytes(),
        1,
        "before any *NODE",
    );
    // the first element cut short by the next keyword
    let mut cut = lines.clone();
    cut.remove(20);
    refused(
        "cut.inp",
        (cut.join("\n") + "\n").as_bytes(),
        21,
        "numbers after the end of an element",
    );
    // the last element cut short by the end of the node data
    let end = lines.iter().position(|l| l.starts_with("*NSET")).unwrap();
    let mut cut = lines.clone();
    cut.remove(end - 1);
    refused(
        "cut2.inp",
        (cut.join("\n") + "\n").as_bytes(),
        end - 1,
        "incomplete element",
    );
    refused("empty.inp", b"*HEADING\nnothing\n", 0, "has no tetrahedra");
}

#[test]
fn malformed_msh_files_are_refused_with_file_and_line() {
    let text = std::fs::read_to_string(meshes().join("design1.msh")).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    // a coordinate that is not a number, in the first node block
    let nodes_at = lines.iter().position(|l| *l == "$Nodes").unwrap();
    let mut bad = lines.clone();
    let coord_line = nodes_at + 4; // header, block header, tag, coordinates
    bad[coord_line] = "67.0 zero 5.8";
    let bad = bad.join("\n") + "\n";
    refused("coord.msh", bad.as_bytes(), coord_line + 1, "node");
    // cut in the middle of the elements (what follows them, gmsh's $Parametrizations of the
    // classified surface, is not read)
    let elements_at = lines.iter().position(|l| *l == "$Elements").unwrap();
    let elements_end = lines.iter().position(|l| *l == "$EndElements").unwrap();
    let cut = lines[..(elements_at + elements_end) / 2].join("\n");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cut.msh");
    std::fs::write(&path, &cut).unwrap();
    let err = read_volume_mesh_native(&path, "mm")
        .unwrap_err()
        .to_string();
    assert!(err.starts_with(&path.display().to_string()), "{err}");
    // not a mesh
    refused("text.msh", b"hello\n", 1, "$MeshFormat");
    // a version read by meshio instead
    let dir = tempfile::tempdir().unwrap();
    let v22 = dir.path().join("old.msh");
    std::fs::write(&v22, "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n").unwrap();
    assert_eq!(volume_reader(&v22).unwrap(), VolumeReader::Meshio);
}

/// `fem DESIGN --mesh X --json` through the native reader and through meshio
/// (RODSTUDY_MESH_READER=meshio): the same numbers, bit for bit, apart from times and paths.
#[test]
fn fem_with_a_user_mesh_gives_the_same_numbers_either_way() {
    let dir = meshes();
    let design = root().join("designs/design1.stl");
    let run = |mesh: &str, reader: &str| -> serde_json::Value {
        let out_dir = tempfile::tempdir().unwrap();
        let out = Command::new(env!("CARGO_BIN_EXE_rodstudy"))
            .arg("fem")
            .arg(&design)
            .arg("--mesh")
            .arg(dir.join(mesh))
            .args(["--force", "7202", "--json", "--out"])
            .arg(out_dir.path())
            .env(MESH_READER_VAR, reader)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        serde_json::from_slice(&out.stdout).unwrap()
    };
    for mesh in ["design1.msh", "quadratic.inp"] {
        let native = run(mesh, "native");
        let meshio = run(mesh, "meshio");
        for key in ["dofs", "elements", "nodes", "criterion"] {
            assert_eq!(native[key], meshio[key], "{mesh}: {key}");
        }
        for case in ["fx", "fy"] {
            let (mut a, mut b) = (native[case].clone(), meshio[case].clone());
            for v in [&mut a, &mut b] {
                let o = v.as_object_mut().unwrap();
                o.remove("vtu");
                o.remove("picture");
            }
            assert_eq!(a, b, "{mesh}: case {case}");
        }
        eprintln!(
            "{mesh}: F_y {} MPa either way; mesh.seconds native {} s, meshio {} s",
            native["fy"]["max_von_mises_away_from_fixed_mpa"],
            native["mesh"]["seconds"],
            meshio["mesh"]["seconds"]
        );
    }
}

/// `fem --mesh … --json` computes the buckling factor by default (with its time and iterations,
/// and the mode file); `--no-buckling` leaves it out and changes nothing of the static analysis.
#[test]
fn fem_no_buckling_leaves_out_buckling_and_nothing_else() {
    let design = root().join("designs/design1.stl");
    let run = |extra: &[&str]| -> (serde_json::Value, bool) {
        let out_dir = tempfile::tempdir().unwrap();
        let out = Command::new(env!("CARGO_BIN_EXE_rodstudy"))
            .arg("fem")
            .arg(&design)
            .arg("--mesh")
            .arg(meshes().join("design1.msh"))
            .args(["--force", "7202", "--json", "--no-pictures", "--out"])
            .arg(out_dir.path())
            .args(extra)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let mode = out_dir.path().join("buckling_mode.vtu").is_file();
        (serde_json::from_slice(&out.stdout).unwrap(), mode)
    };
    let (with, with_mode) = run(&[]);
    let (without, without_mode) = run(&["--no-buckling"]);
    assert!(with["buckling_load_factor"].as_f64().unwrap() > 0.0);
    assert!(with["buckling_s"].as_f64().unwrap() > 0.0);
    assert!(with["buckling_iterations"].as_u64().unwrap() >= 2);
    assert!(with_mode);
    for key in ["buckling_load_factor", "buckling_s", "buckling_iterations"] {
        assert!(without[key].is_null(), "{key}: {}", without[key]);
    }
    assert!(!without_mode);
    for case in ["fx", "fy"] {
        for key in [
            "max_von_mises_away_from_fixed_mpa",
            "max_displacement_mm",
            "estimated_error_rel",
        ] {
            assert_eq!(with[case][key], without[case][key], "{case}: {key}");
        }
    }
}

/// A given mesh is refused, before any solve, when it is not a mesh of the design (another part:
/// the volume differs) or when an element is inverted or has its midside nodes out of order;
/// the element is named by its id and line in the file.
#[test]
fn a_given_mesh_of_another_part_or_with_a_bad_element_is_refused_by_name() {
    let fem = |design: &str, mesh: &Path| {
        let out_dir = tempfile::tempdir().unwrap();
        let out = Command::new(env!("CARGO_BIN_EXE_rodstudy"))
            .arg("fem")
            .arg(root().join(design))
            .arg("--mesh")
            .arg(mesh)
            .args(["--force", "7202", "--json", "--no-pictures", "--out"])
            .arg(out_dir.path())
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2));
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    let inp = meshes().join("quadratic.inp");
    // design 1's mesh given for design 2 (3.90e5 against 4.79e5 mm³)
    let e = fem("designs/design2.stl", &inp);
    assert!(
        e.contains("not a mesh of") && e.contains("differs by -18."),
        "{e}"
    );
    // the first element turned inside out (corners 2 and 3 exchanged, with their edges), then
    // instead two of its midside nodes exchanged
    let text = std::fs::read_to_string(&inp).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let at = 1 + lines
        .iter()
        .position(|l| l.to_ascii_uppercase().starts_with("*ELEMENT"))
        .unwrap();
    let ids: Vec<&str> = lines[at].split(',').map(str::trim).collect();
    assert_eq!(ids.len(), 11, "{}", lines[at]);
    let dir = tempfile::tempdir().unwrap();
    for (name, order, what) in [
        (
            "inverted.inp",
            [0, 2, 1, 3, 6, 5, 4, 7, 9, 8],
            "Jacobian determinant",
        ),
        (
            "swapped.inp",
            [0, 1, 2, 3, 5, 4, 6, 7, 8, 9],
            "is not near the midpoint",
        ),
    ] {
        let element: Vec<&str> = std::iter::once(ids[0])
            .chain(order.iter().map(|&k| ids[1 + k]))
            .collect();
        let mut bad = lines.clone();
        let joined = element.join(",");
        bad[at] = &joined;
        let path = dir.path().join(name);
        std::fs::write(&path, bad.join("\n")).unwrap();
        let e = fem("designs/design1.stl", &path);
        let named = format!("{}:{}: element {}: ", path.display(), at + 1, ids[0]);
        assert!(e.contains(&named) && e.contains(what), "{name}: {e}");
    }
}
