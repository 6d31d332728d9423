//! The fuzz harness in CI: a few hundred damaged and extreme inputs in every format through the
//! real binary (`info` and `mesh --no-core`, `check` for volume meshes), each run within 60 s
//! and 4 GiB. No panic, crash, hang or runaway allocation; every rejection says where. The
//! record of every run is written to `fuzz-ci.tsv` in the test's temporary target directory and
//! the summary to the test output. The long campaign is `examples/fuzz.rs`.

use std::io::Write;
use std::path::Path;

use blmesh::fuzz::run::{Limits, Verdict};

/// Cases of the CI run, and the campaign seed they come from.
const CASES: u64 = 400;
const SEED: u64 = 1;

/// The small shipped surfaces that are mutated besides the shapes built in code.
fn file_seeds() -> Vec<(String, Vec<u8>)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let shared = root.join("../shared/geometries");
    [
        shared.join("mech_test_gapdetection.obj"),
        shared.join("building_wtc2.obj"),
        shared.join("cutcube_cfmesh.stl"),
    ]
    .into_iter()
    .filter_map(|p| Some((p.file_name()?.to_str()?.to_owned(), std::fs::read(&p).ok()?)))
    .collect()
}

#[test]
fn damaged_and_extreme_inputs_never_crash_the_cli() {
    let dir = tempfile::tempdir().unwrap();
    let limits = Limits::default();
    let binary = Path::new(env!("CARGO_BIN_EXE_blmesh"));
    let start = std::time::Instant::now();
    let campaign =
        blmesh::fuzz::campaign(binary, SEED, CASES, &file_seeds(), dir.path(), &limits, 2).unwrap();
    let record = Path::new(env!("CARGO_TARGET_TMPDIR")).join("fuzz-ci.tsv");
    std::fs::write(&record, campaign.table()).unwrap();
    // Straight to stderr, past the test harness's capture: the record of the run in CI's log.
    let _ = writeln!(
        std::io::stderr(),
        "fuzz: {} in {:.1} s; record: {}",
        campaign.summary(CASES),
        start.elapsed().as_secs_f64(),
        record.display()
    );
    let failures: Vec<String> = campaign
        .records
        .iter()
        .filter(|r| r.verdict.is_failure() || r.verdict == Verdict::RejectedUnlocated)
        .map(|r| {
            format!(
                "case {} {} ({}): {:?}: {}",
                r.case, r.command, r.description, r.verdict, r.outcome.stderr
            )
        })
        .collect();
    assert!(failures.is_empty(), "{} failed runs:\n{}", failures.len(), failures.join("\n"));
    let counts = campaign.counts();
    assert!(counts.get(&Verdict::Accepted).is_some_and(|&n| n > 0), "no input was accepted: {counts:?}");
}
