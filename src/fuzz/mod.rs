//! A fuzz harness for the command line: damaged and extreme inputs in every format, run through
//! the real binary (`info`, `mesh --no-core`, and `check` for volume meshes), each run judged
//! ([`run::Verdict`]) and recorded. Test support, in the library so that the CI test
//! (`tests/fuzz.rs`, a few hundred cases) and the long campaign (`examples/fuzz.rs`, 10,000)
//! share it.
//!
//! Case `i` of seed `s` is a pure function of `(s, i)` ([`crate::surface::family::SplitMix64`]):
//! a failure is replayed by its number. See `docs/input-ranges.md`.

pub mod mutate;
pub mod run;
pub mod seeds;

use std::collections::BTreeMap;
use std::ffi::OsString;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

use crate::surface::family::SplitMix64;
use mutate::pick;
use run::{Limits, Outcome, Verdict};
use seeds::Encoding;

/// One generated input.
#[derive(Clone, Debug)]
pub struct Case {
    pub index: u64,
    /// File name with the extension that chooses the reader.
    pub file_name: String,
    pub bytes: Vec<u8>,
    /// What it was made from and what was done to it.
    pub description: String,
    /// A volume mesh (run through `check`), else a surface.
    pub volume: bool,
}

/// Files to mutate besides the shapes built in code: (name with extension, contents).
pub type FileSeeds = [(String, Vec<u8>)];

/// Case `index` of the campaign `seed`.
pub fn case(seed: u64, index: u64, files: &FileSeeds) -> Case {
    let mut rng = SplitMix64::new(seed ^ index.wrapping_mul(0xd1b5_4a32_d192_ed03));
    let mut notes = Vec::new();
    let (stem, extension, mut bytes, text, volume) = match rng.below(14) {
        0 => {
            notes.push("volume mesh".to_owned());
            (format!("volume-{index}"), "vtu", seeds::write_volume(&seeds::volume()), true, true)
        }
        1..=3 if !files.is_empty() => {
            let (name, data) = pick(&mut rng, files);
            let extension = Path::new(name).extension().and_then(|e| e.to_str()).unwrap_or("stl");
            let extension = seeds::Encoding::SURFACES.iter().map(|e| e.extension()).find(|&e| e == extension);
            notes.push(format!("file {name}"));
            (format!("file-{index}"), extension.unwrap_or("stl"), data.clone(), true, false)
        }
        _ => {
            let mut shapes = seeds::shapes();
            let (name, mut shape) = shapes.swap_remove(rng.below(shapes.len()));
            let encoding = *pick(&mut rng, &Encoding::SURFACES);
            notes.push(format!("{name} as {encoding:?}"));
            if rng.chance(0.6) {
                notes.push(mutate::geometric(&mut shape, &mut rng));
            }
            let bytes = seeds::write(&shape, encoding);
            (format!("{name}-{index}"), encoding.extension(), bytes, encoding.is_text(), false)
        }
    };
    // Some cases keep their bytes whole, so that geometric mutations reach the meshing; in
    // real surfaces, one number alone is often changed (a single wild coordinate).
    if text && !volume && notes[0].starts_with("file") && rng.chance(0.5) {
        notes.push(mutate::substitute_number(&mut bytes, &mut rng));
        return Case {
            index,
            file_name: format!("{stem}.{extension}"),
            bytes,
            description: notes.join("; "),
            volume,
        };
    }
    let damages = if rng.chance(0.35) { 0 } else { 1 + rng.below(3) };
    for _ in 0..damages {
        notes.push(mutate::bytes(&mut bytes, text, &mut rng));
    }
    Case { index, file_name: format!("{stem}.{extension}"), bytes, description: notes.join("; "), volume }
}

/// The commands a case runs: `info` and `mesh --no-core` for a surface, `check` for a volume.
fn commands(case: &Case, input: &Path, dir: &Path) -> Vec<(&'static str, Vec<OsString>)> {
    let input = input.as_os_str().to_owned();
    if case.volume {
        return vec![("check", vec!["check".into(), input])];
    }
    let output = dir.join(format!("out-{}.vtu", case.index)).into_os_string();
    vec![
        ("info", vec!["info".into(), input.clone()]),
        ("mesh", vec!["mesh".into(), input, "-o".into(), output, "--no-core".into(), "-q".into()]),
    ]
}

/// One run of one command on one case.
#[derive(Clone, Debug)]
pub struct Record {
    pub case: u64,
    pub command: &'static str,
    pub description: String,
    pub outcome: Outcome,
    pub verdict: Verdict,
}

/// The runs of a campaign, in case order, and their counts.
#[derive(Debug, Default)]
pub struct Campaign {
    pub records: Vec<Record>,
}

impl Campaign {
    /// Runs per verdict.
    pub fn counts(&self) -> BTreeMap<Verdict, usize> {
        let mut counts = BTreeMap::new();
        self.records.iter().for_each(|r| *counts.entry(r.verdict).or_insert(0) += 1);
        counts
    }

    /// Runs per exit (code, signal or timeout).
    pub fn exits(&self) -> BTreeMap<String, usize> {
        let mut counts = BTreeMap::new();
        self.records.iter().for_each(|r| *counts.entry(format!("{:?}", r.outcome.exit)).or_insert(0) += 1);
        counts
    }

    pub fn failures(&self) -> impl Iterator<Item = &Record> {
        self.records.iter().filter(|r| r.verdict.is_failure())
    }

    /// The slowest run and the largest peak memory.
    pub fn extremes(&self) -> (f64, f64) {
        let seconds = self.records.iter().map(|r| r.outcome.seconds).fold(0.0, f64::max);
        let mib = self.records.iter().map(|r| r.outcome.max_rss_mib).fold(0.0, f64::max);
        (seconds, mib)
    }

    /// One line per run: case, command, verdict, exit, seconds, peak MiB, input, first line of
    /// the message.
    pub fn table(&self) -> String {
        let mut out = String::from("case\tcommand\tverdict\texit\tseconds\tpeak_mib\tinput\tmessage\n");
        for r in &self.records {
            let o = &r.outcome;
            let _ = writeln!(
                out,
                "{}\t{}\t{:?}\t{:?}\t{:.3}\t{:.0}\t{}\t{}",
                r.case,
                r.command,
                r.verdict,
                o.exit,
                o.seconds,
                o.max_rss_mib,
                r.description,
                o.first_line().chars().take(300).collect::<String>()
            );
        }
        out
    }

    pub fn summary(&self, cases: u64) -> String {
        let (seconds, mib) = self.extremes();
        format!(
            "{cases} inputs, {} runs; verdicts {:?}; exits {:?}; slowest run {seconds:.2} s; largest peak {mib:.0} MiB",
            self.records.len(),
            self.counts(),
            self.exits()
        )
    }
}

/// Run cases `0..cases` of campaign `seed` on `threads` threads, with inputs and outputs in
/// `dir` (each case's files are removed after its runs).
pub fn campaign(
    binary: &Path,
    seed: u64,
    cases: u64,
    files: &FileSeeds,
    dir: &Path,
    limits: &Limits,
    threads: usize,
) -> std::io::Result<Campaign> {
    let next = AtomicUsize::new(0);
    let records = Mutex::new(Vec::new());
    let error = Mutex::new(None);
    std::thread::scope(|scope| {
        for _ in 0..threads.max(1) {
            scope.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::Relaxed) as u64;
                if i >= cases {
                    return;
                }
                match run_case(binary, &case(seed, i, files), dir, limits) {
                    Ok(mut r) => records.lock().unwrap().append(&mut r),
                    Err(e) => *error.lock().unwrap() = Some(e),
                }
            });
        }
    });
    if let Some(e) = error.into_inner().unwrap() {
        return Err(e);
    }
    let mut records = records.into_inner().unwrap();
    records.sort_by_key(|r| (r.case, r.command));
    Ok(Campaign { records })
}

fn run_case(binary: &Path, case: &Case, dir: &Path, limits: &Limits) -> std::io::Result<Vec<Record>> {
    let input: PathBuf = dir.join(&case.file_name);
    std::fs::write(&input, &case.bytes)?;
    let mut records = Vec::new();
    for (command, args) in commands(case, &input, dir) {
        let args: Vec<&std::ffi::OsStr> = args.iter().map(OsString::as_os_str).collect();
        let outcome = run::run(binary, &args, limits)?;
        let verdict = outcome.verdict(limits);
        records.push(Record {
            case: case.index,
            command,
            description: case.description.clone(),
            outcome,
            verdict,
        });
    }
    let _ = std::fs::remove_file(&input);
    let _ = std::fs::remove_file(dir.join(format!("out-{}.vtu", case.index)));
    Ok(records)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cases_are_a_function_of_seed_and_index() {
        let files = vec![("a.obj".to_owned(), b"v 0 0 0\n".to_vec())];
        for i in 0..40 {
            let (a, b) = (case(7, i, &files), case(7, i, &files));
            assert_eq!((a.bytes, a.description, a.file_name), (b.bytes, b.description, b.file_name));
        }
        assert_ne!(case(7, 1, &files).bytes, case(8, 1, &files).bytes);
    }
}
