//! Interrupted runs never leave half a file. `simulate --report`, `annotate -o`,
//! a cached `simulate` and `rules run --out` are killed (SIGKILL or SIGTERM) at
//! seeded random moments, 20 times in all; after each kill every target path
//! holds nothing, the previous version, or the complete new one (outputs are
//! deterministic, so "complete" means byte-identical to an uninterrupted run).

mod common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_framewright"))
}

fn model(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/models")
        .join(name)
}

/// splitmix64: a seeded sequence of kill moments and signals, the same on every run.
struct Seeded(u64);

impl Seeded {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// A fraction in [0, 1).
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Every regular file under `dir` (relative path → bytes). Hidden entries are the
/// writers' temporary files and folders (`.name.XXXX.tmp`, a report's `.name.PID.old`),
/// not target paths, and are left out.
fn files_under(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    fn walk(root: &Path, dir: &Path, out: &mut BTreeMap<PathBuf, Vec<u8>>) {
        let Ok(entries) = std::fs::read_dir(dir) else {
            return;
        };
        for e in entries.flatten() {
            let path = e.path();
            let name = e.file_name().to_string_lossy().into_owned();
            if name.starts_with('.') {
                continue;
            }
            if path.is_dir() {
                walk(root, &path, out);
            } else {
                let rel = path.strip_prefix(root).unwrap().to_path_buf();
                out.insert(rel, std::fs::read(&path).unwrap());
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(dir, dir, &mut out);
    out
}

/// One command whose outputs live under `area`.
struct Case {
    name: &'static str,
    args: Vec<String>,
    area: PathBuf,
}

impl Case {
    fn command(&self) -> Command {
        let mut c = bin();
        c.args(&self.args)
            .stdout(Stdio::null())
            .stderr(Stdio::null());
        c
    }

    /// Runs to completion; returns how long it took.
    fn run_whole(&self) -> Duration {
        let t = Instant::now();
        let status = self.command().status().unwrap();
        assert!(status.success(), "{}: {:?} failed", self.name, self.args);
        t.elapsed()
    }
}

/// Kills the run after `delay` with SIGKILL or SIGTERM; waits for it to end.
fn run_and_kill(case: &Case, delay: Duration, sigkill: bool) {
    let mut child = case.command().spawn().unwrap();
    std::thread::sleep(delay);
    if sigkill {
        let _ = child.kill();
    } else {
        let _ = Command::new("kill")
            .arg("-TERM")
            .arg(child.id().to_string())
            .status();
    }
    let _ = child.wait();
}

/// After a kill each target file is absent, the previous version or the complete new one.
fn assert_no_partial_file(
    case: &Case,
    before: &BTreeMap<PathBuf, Vec<u8>>,
    complete: &BTreeMap<PathBuf, Vec<u8>>,
    kill: usize,
) {
    for (path, bytes) in files_under(&case.area) {
        let ok = before.get(&path) == Some(&bytes) || complete.get(&path) == Some(&bytes);
        assert!(
            ok,
            "{} kill {kill}: {} is neither the previous nor the complete file ({} bytes)",
            case.name,
            path.display(),
            bytes.len()
        );
    }
}

#[test]
fn killed_runs_leave_no_partial_file() {
    let scratch = tempfile::tempdir().unwrap();
    let s = |p: &str| scratch.path().join(p);
    let tm1 = model("tm1.ifc");
    let tm1 = tm1.to_str().unwrap();
    // A rule program with enough output that a kill can land while it is written.
    std::fs::create_dir_all(s("rules")).unwrap();
    std::fs::write(
        s("rules/big.dl"),
        ".decl n(x: number)\nn(0).\nn(x + 1) :- n(x), x < 40000.\n\
         .decl sq(x: number, y: number)\nsq(x, x * x) :- n(x).\n\
         .output n\n.output sq\n",
    )
    .unwrap();
    let path_str = |p: PathBuf| p.to_str().unwrap().to_string();
    let args = |v: &[&str]| v.iter().map(|a| a.to_string()).collect::<Vec<_>>();
    let cases = [
        Case {
            name: "simulate --report",
            args: [
                args(&["simulate", tm1, "--no-cache", "--report"]),
                vec![path_str(s("report/run"))],
            ]
            .concat(),
            area: s("report"),
        },
        Case {
            name: "annotate -o",
            args: [
                args(&["annotate", tm1, "-o"]),
                vec![path_str(s("ann/out.ifc"))],
            ]
            .concat(),
            area: s("ann"),
        },
        Case {
            name: "cached simulate",
            args: [
                args(&["simulate", tm1, "--json", "--cache"]),
                vec![path_str(s("cache"))],
            ]
            .concat(),
            area: s("cache"),
        },
        Case {
            name: "rules run --out",
            args: [
                args(&["rules", "run"]),
                vec![
                    path_str(s("rules/big.dl")),
                    "--out".into(),
                    path_str(s("csv")),
                ],
            ]
            .concat(),
            area: s("csv"),
        },
    ];
    for case in &cases {
        std::fs::create_dir_all(&case.area).unwrap();
    }
    let mut rng = Seeded(18);
    let mut kills = 0;
    for case in &cases {
        // The complete outputs, and how long a whole run takes (kills land inside it).
        let took = case.run_whole();
        let complete = files_under(&case.area);
        assert!(!complete.is_empty(), "{} wrote nothing", case.name);
        for k in 0..5 {
            // Every other kill starts from an empty area, the rest from the complete outputs.
            if k % 2 == 0 {
                std::fs::remove_dir_all(&case.area).unwrap();
                std::fs::create_dir_all(&case.area).unwrap();
            }
            let before = files_under(&case.area);
            let delay = took.mul_f64(rng.unit() * 1.2);
            let sigkill = rng.next().is_multiple_of(2);
            run_and_kill(case, delay, sigkill);
            assert_no_partial_file(case, &before, &complete, k);
            kills += 1;
        }
        // The area is still usable: a whole run afterwards completes the outputs.
        case.run_whole();
        assert_eq!(files_under(&case.area), complete, "{}", case.name);
    }
    assert_eq!(kills, 20);
}

#[test]
fn a_report_run_removes_the_staging_folders_that_killed_runs_left() {
    let scratch = tempfile::tempdir().unwrap();
    let report = scratch.path().join("run");
    // Process ids beyond Linux's largest (2^22): no such process can be running.
    let dead = scratch.path().join(".run.4194399.tmp");
    let dead_old = scratch.path().join(".run.4194398.old");
    // A live process's folder (this test's own) and another report's stay.
    let live = scratch
        .path()
        .join(format!(".run.{}.tmp", std::process::id()));
    let other = scratch.path().join(".other.4194399.tmp");
    for d in [&dead, &dead_old, &live, &other] {
        std::fs::create_dir_all(d).unwrap();
        std::fs::write(d.join("index.html"), "half").unwrap();
    }
    let status = bin()
        .args([
            "simulate",
            model("tm1.ifc").to_str().unwrap(),
            "--no-cache",
            "--report",
        ])
        .arg(&report)
        .stdout(Stdio::null())
        .status()
        .unwrap();
    assert!(status.success());
    assert!(report.join("index.html").exists());
    if !Path::new("/proc/self").exists() {
        common::skip::missing_tool(
            "/proc (the process list)",
            "a Linux system with /proc mounted",
        );
        return;
    }
    assert!(
        !dead.exists() && !dead_old.exists(),
        "dead runs' staging folders remain"
    );
    assert!(
        live.exists() && other.exists(),
        "a live run's or another report's folder was removed"
    );
}
