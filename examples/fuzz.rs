//! The long fuzz campaign (not in CI): `cargo run --release --example fuzz -- [CASES] [SEED]`
//! runs CASES (default 10,000) inputs of campaign SEED (default 1) through `info` and
//! `mesh --no-core` (`check` for volume meshes) of the release binary beside this example (or
//! `$BLMESH_BIN`), each
//! within 60 s and 4 GiB, and prints the counts; the record of every run goes to
//! `target/fuzz-campaign-SEED.tsv`. Exits non-zero if any run panicked, crashed, hung or ran out
//! of memory, or if a rejection named no place. The `info` and `check` runs of the same inputs
//! are in the record too.

use std::path::{Path, PathBuf};

use blmesh::fuzz::run::{Limits, Verdict};

fn main() -> std::process::ExitCode {
    let mut args = std::env::args().skip(1);
    let cases: u64 = args.next().map_or(10_000, |a| a.parse().expect("CASES is a number"));
    let seed: u64 = args.next().map_or(1, |a| a.parse().expect("SEED is a number"));
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let exe = std::env::current_exe().expect("the example's path");
    // target/release/examples/fuzz -> target/release/blmesh, unless BLMESH_BIN names another.
    let beside = || exe.parent().and_then(Path::parent).expect("a target directory").join("blmesh");
    let binary: PathBuf = std::env::var_os("BLMESH_BIN").map_or_else(beside, PathBuf::from);
    assert!(binary.exists(), "build the binary first: cargo build --release ({} missing)", binary.display());
    let shared = root.join("../shared/geometries");
    let files: Vec<(String, Vec<u8>)> =
        ["mech_test_gapdetection.obj", "building_wtc2.obj", "cutcube_cfmesh.stl"]
            .iter()
            .filter_map(|name| Some((name.to_string(), std::fs::read(shared.join(name)).ok()?)))
            .chain(
                ["box.stl"].iter().filter_map(|n| {
                    Some((n.to_string(), std::fs::read(root.join("examples").join(n)).ok()?))
                }),
            )
            .collect();
    let dir = tempfile::tempdir().expect("a temporary directory");
    let threads = std::thread::available_parallelism().map_or(2, |n| n.get());
    let limits = Limits::default();
    let start = std::time::Instant::now();
    let campaign = blmesh::fuzz::campaign(&binary, seed, cases, &files, dir.path(), &limits, threads)
        .expect("the campaign runs");
    let record = root.join("target").join(format!("fuzz-campaign-{seed}.tsv"));
    std::fs::write(&record, campaign.table()).expect("the record is written");
    println!("{} in {:.0} s", campaign.summary(cases), start.elapsed().as_secs_f64());
    println!("record: {}", record.display());
    let bad: Vec<_> = campaign
        .records
        .iter()
        .filter(|r| r.verdict.is_failure() || r.verdict == Verdict::RejectedUnlocated)
        .collect();
    for r in &bad {
        println!(
            "case {} {}: {:?}: {} -- {}",
            r.case,
            r.command,
            r.verdict,
            r.description,
            r.outcome.first_line()
        );
    }
    if bad.is_empty() {
        std::process::ExitCode::SUCCESS
    } else {
        std::process::ExitCode::FAILURE
    }
}
