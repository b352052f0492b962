//! A full disk while framewright writes: the run fails with a message naming the file it
//! could not write, the previous file stays as it was, and no partial or temporary file is
//! left. The outputs go to a small tmpfs mounted for the test; where mounting is not allowed
//! (not root, no CAP_SYS_ADMIN) the test says so and skips.

mod common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_framewright"))
}

/// A tmpfs of `size` mounted on a fresh folder, unmounted when dropped.
struct SmallDisk {
    dir: tempfile::TempDir,
}

impl SmallDisk {
    fn mount(size: &str) -> Option<SmallDisk> {
        let dir = tempfile::tempdir().ok()?;
        let out = Command::new("mount")
            .args(["-t", "tmpfs", "-o", &format!("size={size}"), "tmpfs"])
            .arg(dir.path())
            .output()
            .ok()?;
        if !out.status.success() {
            common::skip::missing_tool(
                &format!(
                    "a tmpfs mount ({})",
                    String::from_utf8_lossy(&out.stderr).trim()
                ),
                "run the tests as root or with CAP_SYS_ADMIN, as .ci/run does",
            );
            return None;
        }
        Some(SmallDisk { dir })
    }
    fn path(&self) -> &Path {
        self.dir.path()
    }
}

impl Drop for SmallDisk {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(self.dir.path()).status();
    }
}

/// Every file under `dir`, hidden ones too (relative path → bytes).
fn files_under(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    fn walk(root: &Path, dir: &Path, out: &mut BTreeMap<PathBuf, Vec<u8>>) {
        for e in std::fs::read_dir(dir).unwrap().flatten() {
            let path = e.path();
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

/// Fills what is left of `disk` with one file, so the next write of any size fails.
fn fill(disk: &Path) {
    use std::io::Write;
    let mut f = std::fs::File::create(disk.join("filler")).unwrap();
    let block = [0u8; 4096];
    while f.write_all(&block).is_ok() {}
    // The last partial block, byte by byte.
    while f.write_all(&[0]).is_ok() && f.flush().is_ok() {}
}

/// Runs `args` on the filled disk; returns whether it succeeded and its standard error,
/// after checking it did not panic and left every file under `disk` as it was.
fn run_on_full_disk(args: &[&str], disk: &Path) -> (bool, String) {
    let _ = std::fs::remove_file(disk.join("filler"));
    fill(disk);
    let before = files_under(disk);
    let out = bin().args(args).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(
        !err.contains("panicked"),
        "{args:?} panicked on a full disk: {err}"
    );
    assert_eq!(
        files_under(disk),
        before,
        "{args:?} left a partial or temporary file, or changed the previous one ({err})"
    );
    (out.status.success(), err)
}

/// Runs `args`, which must fail on the full disk and say why; returns its standard error.
fn fails_on_full_disk(args: &[&str], disk: &Path) -> String {
    let (ok, err) = run_on_full_disk(args, disk);
    assert!(!ok, "{args:?} succeeded on a full disk");
    assert!(
        err.to_lowercase().contains("no space left on device"),
        "{args:?}: the error says why: {err}"
    );
    err
}

#[test]
fn a_full_disk_fails_the_run_and_leaves_the_previous_files() {
    let Some(disk) = SmallDisk::mount("16k") else {
        return;
    };
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let tm1 = root.join("examples/models/tm1.ifc");
    let tm1 = tm1.to_str().unwrap();
    let scratch = tempfile::tempdir().unwrap();
    // 40,001 numbers and their squares: some 600 KB of CSV.
    let prog = scratch.path().join("big.dl");
    std::fs::write(
        &prog,
        ".decl n(x: number)\nn(0).\nn(x + 1) :- n(x), x < 40000.\n\
         .decl sq(x: number, y: number)\nsq(x, x * x) :- n(x).\n\
         .output n\n.output sq\n",
    )
    .unwrap();
    let d = |p: &str| disk.path().join(p);
    // Previous outputs, small enough to fit: they must survive the failed runs.
    for (file, old) in [("csv/n.csv", "0\n"), ("report/index.html", "<p>old</p>\n")] {
        std::fs::create_dir_all(d(file).parent().unwrap()).unwrap();
        std::fs::write(d(file), old).unwrap();
    }
    std::fs::create_dir_all(d("cache")).unwrap();

    let err = fails_on_full_disk(
        &[
            "rules",
            "run",
            prog.to_str().unwrap(),
            "--out",
            d("csv").to_str().unwrap(),
        ],
        disk.path(),
    );
    assert!(
        err.contains(d("csv").to_str().unwrap()),
        "names the file: {err}"
    );

    let err = fails_on_full_disk(
        &[
            "simulate",
            tm1,
            "--no-cache",
            "--report",
            d("report").to_str().unwrap(),
        ],
        disk.path(),
    );
    assert!(
        err.contains(d("report").to_str().unwrap()),
        "names the file: {err}"
    );

    // The cache only saves time: a run whose entry cannot be stored still reports, and
    // says which entry it could not store.
    let (_, err) = run_on_full_disk(
        &[
            "simulate",
            tm1,
            "--json",
            "--cache",
            d("cache").to_str().unwrap(),
        ],
        disk.path(),
    );
    assert!(
        err.contains(d("cache").to_str().unwrap())
            && err.to_lowercase().contains("no space left on device"),
        "names the file and the reason: {err}"
    );
}
