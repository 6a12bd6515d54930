//! The adaptive loop's gmsh session (`pipeline/mesh_rod.py serve`, [`GmshSession`]) against
//! meshes made in fresh processes (`mesh_rod.py mesh`): the same classified surface and the same
//! meshes, file for file, for a uniform first mesh and two size-field meshes after it (each made
//! on the model the session built ahead from the cached classification, under the previous
//! mesh's options); a failed request ends the session with gmsh's reason. Needs the pipeline's Python environment (gmsh).

use std::path::{Path, PathBuf};

use rodstudy::mesher::gmsh_session::GmshSession;
use rodstudy::mesher::size_field::write_size_field;
use rodstudy::mesher::volume::read_volume_mesh_native;
use rodstudy::mesher::{MeshRequest, mesh_stl_with};

fn python() -> PathBuf {
    rodstudy::python_env::python().expect("the pipeline's Python environment")
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn script() -> PathBuf {
    root().join("pipeline/mesh_rod.py")
}

fn stl() -> PathBuf {
    root().join("designs/design1.stl")
}

fn bytes(path: &Path) -> Vec<u8> {
    std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn a_session_makes_the_meshes_of_fresh_processes_file_for_file() {
    let dir = tempfile::tempdir().unwrap();
    let (served, fresh) = (dir.path().join("served"), dir.path().join("fresh"));
    let mut session =
        GmshSession::start(&python(), &script(), &stl(), &served.join("classified.msh")).unwrap();
    std::fs::create_dir_all(&served).unwrap();
    let first = session.mesh(8.0, None, &served.join("m0"), "rod").unwrap();
    assert!(first.report.failed_attempts.is_empty() && first.report.fallback.is_none());
    // a size map graded along the rod (2.5 mm at the crank end to 10 mm beyond 150 mm), from
    // the first mesh as the loop makes one
    let sizes: Vec<f64> = first
        .mesh
        .nodes()
        .iter()
        .map(|p| (2.5e-3 + 0.05 * p[0].abs()).min(10e-3))
        .collect();
    let field = dir.path().join("size_field.bin");
    write_size_field(&field, &first.mesh, &sizes, 1e3, None).unwrap();
    let second = session
        .mesh(10.0, Some(&field), &served.join("m1"), "rod")
        .unwrap();
    assert!(second.report.size_mm == 10.0 && second.mesh.n_elements() > 0);
    // and the other way round: fine at the piston end
    let sizes: Vec<f64> = second
        .mesh
        .nodes()
        .iter()
        .map(|p| (10e-3 - 0.04 * p[0].abs()).max(3e-3))
        .collect();
    let field2 = dir.path().join("size_field2.bin");
    write_size_field(&field2, &second.mesh, &sizes, 1e3, None).unwrap();
    let third = session
        .mesh(8.0, Some(&field2), &served.join("m2"), "rod")
        .unwrap();

    let geometry = fresh.join("classified.msh");
    // the same meshes in fresh processes, each `mesh_rod.py mesh` with the classified-surface cache
    let in_fresh_process = |size_mm, size_field, out: &str| {
        let request = MeshRequest {
            size_mm,
            size_field,
            geometry: Some(&geometry),
            name: Some("rod"),
            native_read: true,
        };
        mesh_stl_with(&python(), &script(), &stl(), &request, &fresh.join(out)).unwrap()
    };
    let a = in_fresh_process(8.0, None, "m0");
    let b = in_fresh_process(10.0, Some(&field), "m1");
    let c = in_fresh_process(8.0, Some(&field2), "m2");
    assert_eq!(
        bytes(&served.join("classified.msh")),
        bytes(&geometry),
        "the classified surface"
    );
    for (s, f) in [(&first, &a), (&second, &b), (&third, &c)] {
        assert_eq!(s.report.elements, f.report.elements);
        assert!(
            bytes(&s.report.msh) == bytes(&f.report.msh),
            "{} and {} differ",
            s.report.msh.display(),
            f.report.msh.display()
        );
    }
    // the second mesh followed the field: finer than the first near the crank end
    assert!(second.mesh.n_elements() > first.mesh.n_elements());
    // each mesh says where its time went: gmsh's phases from its log, within the mesher's own
    // total, HXT's optimisation within the 3D mesh, and the read measured on this side
    for m in [&first, &second, &third, &a, &b, &c] {
        let p = m.report.phases_s.expect("the mesher's phases");
        let parts = [
            p.model,
            p.mesh_1d,
            p.mesh_2d,
            p.mesh_3d,
            p.order_2,
            p.qualities,
            p.write,
        ];
        assert!(
            parts
                .iter()
                .chain([&p.hxt_optimise, &p.read])
                .all(|x| x.is_some_and(|v| v >= 0.0)),
            "{p:?}"
        );
        let sum: f64 = parts.iter().flatten().sum();
        assert!(
            sum <= m.report.seconds_total + 1e-3,
            "{p:?} against {}",
            m.report.seconds_total
        );
        assert!(p.hxt_optimise <= p.mesh_3d, "{p:?}");
    }
    // the meshes read natively are written binary and read as their ASCII print: the same mesh
    // written ASCII (the .rodmesh route writes the .msh in ASCII) reads to the same bits
    assert!(second.report.msh_binary && b.report.msh_binary);
    let ascii = MeshRequest {
        size_mm: 10.0,
        size_field: Some(&field),
        geometry: Some(&geometry),
        name: Some("rod"),
        native_read: false,
    };
    let ascii = mesh_stl_with(&python(), &script(), &stl(), &ascii, &fresh.join("m1a")).unwrap();
    assert!(!ascii.report.msh_binary);
    let from_ascii = read_volume_mesh_native(&ascii.report.msh, "mm").unwrap();
    let exact = read_volume_mesh_native(&second.report.msh, "mm").unwrap();
    assert_eq!(from_ascii.elements(), second.mesh.elements());
    let same = |m: &rodstudy::fem::TetMesh| {
        m.nodes()
            .iter()
            .flatten()
            .zip(from_ascii.nodes().iter().flatten())
            .filter(|(x, y)| x.to_bits() != y.to_bits())
            .count()
    };
    assert_eq!(same(&second.mesh), 0, "the binary mesh read as ASCII");
    // (and read exactly, the binary file's coordinates are not the ASCII print's)
    assert!(same(&exact) > 0);
    // the classification is in the first mesh's model, not in a later one's
    let model = |m: &rodstudy::mesher::MeshedRod| m.report.phases_s.unwrap().model.unwrap();
    assert!(
        model(&first) > 2.0 * model(&second),
        "{} vs {}",
        model(&first),
        model(&second)
    );
}

#[test]
fn a_failed_request_ends_the_session_with_the_reason() {
    let dir = tempfile::tempdir().unwrap();
    let mut session = GmshSession::start(
        &python(),
        &script(),
        &stl(),
        &dir.path().join("classified.msh"),
    )
    .unwrap();
    let missing = dir.path().join("no_such_field.bin");
    let err = session
        .mesh(10.0, Some(&missing), &dir.path().join("m0"), "rod")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("no such size field file") && err.contains("no_such_field.bin"),
        "{err}"
    );
    let err = session
        .mesh(8.0, None, &dir.path().join("m1"), "rod")
        .unwrap_err()
        .to_string();
    assert!(err.contains("the gmsh session has ended"), "{err}");
}

/// gmsh hands HXT the surface vertices in the order of their memory
/// addresses, and HXT's optimiser broke its ties by it, so one session meshing the same request
/// again (after other meshes, with other paths) could make another mesh: design 5's third
/// adaptive mesh (its half model) came out with 12,228 or 12,229 nodes, and a fresh clone in
/// another folder reported another design 5. Every mesh is now made in a thread with an
/// allocator arena of its own (`mesh_rod.py`, `fixed_allocator`): the same request, four times in
/// one session into folders of different lengths, and once in a fresh process, gives one file.
#[test]
fn the_same_request_gives_the_same_mesh_whatever_came_before() {
    let dir = tempfile::tempdir().unwrap();
    // design 5 through the adaptive loop, for its half surface, classification and third size map
    let run = dir.path().join("loop");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_rodstudy"))
        .args([
            "fem",
            "designs/design5.stl",
            "--json",
            "--no-pictures",
            "--no-buckling",
        ])
        .arg("--out")
        .arg(&run)
        .current_dir(root())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mesh_dir = run.join("mesh");
    let half = mesh_dir.join("rod_frame.stl");
    let field = mesh_dir.join("adapt2/size_field.bin");
    assert!(half.is_file() && field.is_file());
    let classified = std::fs::read_dir(&mesh_dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| {
            let n = p.file_name().unwrap().to_string_lossy().into_owned();
            n.starts_with("classified-") && n.ends_with(".msh")
        })
        .expect("the loop's classified surface");
    let geometry = dir.path().join("classified.msh");
    std::fs::copy(&classified, &geometry).unwrap();
    let meta = |p: &Path| PathBuf::from(format!("{}.json", p.display()));
    std::fs::copy(meta(&classified), meta(&geometry)).unwrap();
    let mut session = GmshSession::start(&python(), &script(), &half, &geometry).unwrap();
    let outs = [
        "a",
        "bbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbb",
        "c/c/c/c/c",
        "d",
    ];
    let files: Vec<Vec<u8>> = outs
        .iter()
        .map(|o| {
            let m = session
                .mesh(10.0, Some(&field), &dir.path().join(o), "rod")
                .unwrap();
            bytes(&m.report.msh)
        })
        .collect();
    let request = MeshRequest {
        size_mm: 10.0,
        size_field: Some(&field),
        geometry: Some(&geometry),
        name: Some("rod"),
        native_read: true,
    };
    let fresh =
        mesh_stl_with(&python(), &script(), &half, &request, &dir.path().join("e")).unwrap();
    for (o, f) in outs.iter().zip(&files) {
        assert!(
            f == &files[0],
            "the mesh made into {o} differs from the first"
        );
    }
    assert!(
        bytes(&fresh.report.msh) == files[0],
        "the fresh process's mesh differs"
    );
}
