//! `study --shard K/N` and `merge`: the shards of a split study merge into byte-for-byte the
//! reports of a one-machine study; incomplete, overlapping or mismatched shards are refused with
//! a message that names the problem. Stages 1–2 (`--skip-fem`): the split and the merge do not
//! depend on which stages run, and these are fast.

use std::path::Path;
use std::process::{Command, Output};

fn rodstudy(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rodstudy"))
        .args(args)
        .output()
        .unwrap()
}

fn ok(o: &Output) {
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}

fn study(designs: &Path, out: &Path, extra: &[&str]) {
    let mut args = vec![
        "study",
        "--skip-fem",
        "--no-cache",
        "--designs",
        designs.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    ok(&rodstudy(&args));
}

#[test]
fn three_shards_merge_into_the_one_machine_reports() {
    let designs = Path::new(env!("CARGO_MANIFEST_DIR")).join("designs");
    let tmp = tempfile::tempdir().unwrap();
    let t = tmp.path();
    study(&designs, &t.join("whole"), &[]);
    let mut shard_ids = Vec::new();
    for k in 1..=3 {
        let out = t.join(format!("s{k}"));
        study(&designs, &out, &["--shard", &format!("{k}/3")]);
        let r: serde_json::Value =
            serde_json::from_slice(&std::fs::read(out.join("results.json")).unwrap()).unwrap();
        assert_eq!(r["shard"]["shard"]["index"], k);
        for d in r["designs"].as_array().unwrap() {
            shard_ids.push(d["mass"]["id"].as_str().unwrap().to_string());
        }
    }
    // every design in exactly one shard
    shard_ids.sort();
    assert_eq!(
        shard_ids,
        ["design1", "design2", "design3", "design4", "design5"]
    );
    let dirs: Vec<String> = (1..=3)
        .map(|k| t.join(format!("s{k}")).display().to_string())
        .collect();
    let merged = t.join("merged");
    let mut args = vec!["merge"];
    args.extend(dirs.iter().map(|s| s.as_str()));
    args.extend(["--out", merged.to_str().unwrap()]);
    ok(&rodstudy(&args));
    for f in [
        "results.json",
        "ranking.csv",
        "ranking.md",
        "mass_properties.csv",
        "pareto.csv",
        "pareto.svg",
        "index.html",
        "pin_force.svg",
        "design3/pin_force.csv",
        "design3/pin_force.svg",
    ] {
        let a = std::fs::read(t.join("whole").join(f)).unwrap();
        let b = std::fs::read(merged.join(f)).unwrap();
        assert!(a == b, "{f} differs between the whole study and the merge");
    }

    // a missing shard is named
    let o = rodstudy(&[
        "merge",
        &dirs[0],
        &dirs[2],
        "--out",
        t.join("m2").to_str().unwrap(),
    ]);
    assert_ne!(o.status.code(), Some(0));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("missing shard(s): 2/3"), "{e}");
    // the same shard twice
    let o = rodstudy(&[
        "merge",
        &dirs[0],
        &dirs[0],
        &dirs[1],
        "--out",
        t.join("m3").to_str().unwrap(),
    ]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("appears twice"), "{e}");
    // a shard run with other settings
    let config = t.join("nograv.toml");
    std::fs::write(&config, "[driven]\ngravity = false\n").unwrap();
    let other = t.join("s2-other");
    study(
        &designs,
        &other,
        &["--shard", "2/3", "--config", config.to_str().unwrap()],
    );
    let o = rodstudy(&[
        "merge",
        &dirs[0],
        other.to_str().unwrap(),
        &dirs[2],
        "--out",
        t.join("m4").to_str().unwrap(),
    ]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("settings differ"), "{e}");
    // a whole study is not a shard
    let o = rodstudy(&[
        "merge",
        t.join("whole").to_str().unwrap(),
        "--out",
        t.join("m5").to_str().unwrap(),
    ]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("not a shard"), "{e}");
    // a shard of the same ids in another designs folder (sweeps name their rods alike)
    let copy = t.join("designs-copy");
    std::fs::create_dir_all(&copy).unwrap();
    for e in std::fs::read_dir(&designs).unwrap().flatten() {
        std::fs::copy(e.path(), copy.join(e.file_name())).unwrap();
    }
    let elsewhere = t.join("s2-elsewhere");
    study(&copy, &elsewhere, &["--shard", "2/3"]);
    let o = rodstudy(&[
        "merge",
        &dirs[0],
        elsewhere.to_str().unwrap(),
        &dirs[2],
        "--out",
        t.join("m6").to_str().unwrap(),
    ]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("read one designs folder"), "{e}");
    // the merged reports into one of the shards' folders
    let o = rodstudy(&["merge", &dirs[0], &dirs[1], &dirs[2], "--out", &dirs[1]]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("--out is one of the shards"), "{e}");
}

/// With an engine (the example pressure trace over 720°), the merge recomputes each design's
/// history as the study did: gas force included, the `gas_force_n` column kept; the merged
/// reports are the one-machine study's, byte for byte.
#[test]
fn shards_of_an_engine_study_merge_into_its_reports() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config = root.join("pipeline/examples/engine.toml");
    let config = config.to_str().unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let t = tmp.path();
    let designs = t.join("designs");
    std::fs::create_dir(&designs).unwrap();
    for stem in ["design1", "design5"] {
        for ext in ["stl", "toml"] {
            std::fs::copy(
                root.join("designs").join(format!("{stem}.{ext}")),
                designs.join(format!("{stem}.{ext}")),
            )
            .unwrap();
        }
    }
    study(&designs, &t.join("whole"), &["--config", config]);
    for k in 1..=2 {
        study(
            &designs,
            &t.join(format!("s{k}")),
            &["--config", config, "--shard", &format!("{k}/2")],
        );
    }
    ok(&rodstudy(&[
        "merge",
        t.join("s1").to_str().unwrap(),
        t.join("s2").to_str().unwrap(),
        "--out",
        t.join("merged").to_str().unwrap(),
    ]));
    for f in [
        "results.json",
        "ranking.csv",
        "design1/pin_force.csv",
        "design5/pin_force.csv",
    ] {
        let whole = std::fs::read(t.join("whole").join(f)).unwrap();
        assert_eq!(
            whole,
            std::fs::read(t.join("merged").join(f)).unwrap(),
            "{f}"
        );
    }
    let csv = std::fs::read_to_string(t.join("merged/design1/pin_force.csv")).unwrap();
    assert!(
        csv.lines().next().unwrap().ends_with(",gas_force_n"),
        "{csv:.200}"
    );
}
