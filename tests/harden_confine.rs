//! A rule file passed around must not read or write outside its folders:
//! `.include` stays under the rule file's folder (or `--rules-dir`),
//! `.input`/`.output` stay under `--facts`/`--out`, symbolic links out are
//! refused, and a refused file's contents never appear in the error.

use std::path::Path;
use std::process::{Command, Output};

/// Content of the file outside the folder: it must never show up in a message.
const SECRET: &str = "SECRET-LINE-root:x:0:0";

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_framewright"))
}

fn write(path: &Path, text: &str) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(path, text).unwrap();
}

/// A scratch area: `rules/` (the rule folder), `facts/`, `out/` and a `secret.dl` beside them.
struct Area {
    dir: tempfile::TempDir,
}

impl Area {
    fn new() -> Self {
        let a = Area {
            dir: tempfile::tempdir().unwrap(),
        };
        write(&a.p("secret.dl"), &format!("{SECRET}\n"));
        write(&a.p("secret.facts"), &format!("{SECRET}\n"));
        std::fs::create_dir_all(a.p("facts")).unwrap();
        std::fs::create_dir_all(a.p("out")).unwrap();
        a
    }
    fn p(&self, rel: &str) -> std::path::PathBuf {
        self.dir.path().join(rel)
    }
    fn rules(&self, args: &[&str]) -> Output {
        bin()
            .current_dir(self.dir.path())
            .arg("rules")
            .args(args)
            .output()
            .unwrap()
    }
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn assert_refused(o: &Output, must_contain: &[&str]) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        !err.contains(SECRET),
        "the refused file's content leaked: {err}"
    );
    assert!(
        !String::from_utf8_lossy(&o.stdout).contains(SECRET),
        "leaked on stdout"
    );
    for m in must_contain {
        assert!(err.contains(m), "missing {m:?} in: {err}");
    }
}

#[test]
fn include_of_an_absolute_path_is_refused_without_reading_it() {
    let a = Area::new();
    let secret = a.p("secret.dl");
    write(
        &a.p("rules/main.dl"),
        &format!(
            ".decl e(x: number)\n.include \"{}\"\ne(1).\n",
            secret.display()
        ),
    );
    let o = a.rules(&["check", "rules/main.dl"]);
    let folder = a.p("rules").canonicalize().unwrap();
    assert_refused(
        &o,
        &[
            "`.include` refused",
            "rules/main.dl:2:",
            &folder.display().to_string(),
            "--rules-dir",
        ],
    );
}

#[test]
fn include_with_dotdot_out_of_the_folder_is_refused() {
    let a = Area::new();
    write(&a.p("rules/main.dl"), ".include \"../secret.dl\"\n");
    let o = a.rules(&["check", "rules/main.dl"]);
    assert_refused(&o, &["`.include` refused", "rules/main.dl:1:"]);
}

#[test]
fn include_through_a_symlink_out_of_the_folder_is_refused() {
    let a = Area::new();
    std::os::unix::fs::symlink(a.p("secret.dl"), a.p("rules_link_target")).unwrap();
    std::fs::create_dir_all(a.p("rules")).unwrap();
    // A link to a file, and a link to a folder outside.
    std::os::unix::fs::symlink(a.p("secret.dl"), a.p("rules/inside.dl")).unwrap();
    std::os::unix::fs::symlink(a.dir.path(), a.p("rules/up")).unwrap();
    write(&a.p("rules/one.dl"), ".include \"inside.dl\"\n");
    write(&a.p("rules/two.dl"), ".include \"up/secret.dl\"\n");
    for f in ["rules/one.dl", "rules/two.dl"] {
        let o = a.rules(&["check", f]);
        assert_refused(&o, &["`.include` refused", &format!("{f}:1:")]);
    }
}

#[test]
fn includes_inside_the_folder_still_work_and_rules_dir_widens_it() {
    let a = Area::new();
    write(&a.p("rules/common.dl"), ".decl e(x: number)\ne(1).\n");
    // A nested file may include back up, as long as it stays in the top-level folder.
    write(&a.p("rules/sub/mid.dl"), ".include \"../common.dl\"\n");
    write(
        &a.p("rules/main.dl"),
        ".include \"sub/mid.dl\"\n.output e(IO=stdout)\n",
    );
    let o = a.rules(&["run", "rules/main.dl", "-D", "out"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("\n1\n"));

    // A shared file one level up is refused by default and allowed with --rules-dir.
    write(&a.p("shared/decls.dl"), ".decl f(x: number)\nf(2).\n");
    write(
        &a.p("rules/uses_shared.dl"),
        ".include \"../shared/decls.dl\"\n.output f(IO=stdout)\n",
    );
    let o = a.rules(&["run", "rules/uses_shared.dl", "-D", "out"]);
    assert_refused(&o, &["`.include` refused"]);
    let root = a.dir.path().to_str().unwrap();
    let o = a.rules(&[
        "run",
        "rules/uses_shared.dl",
        "-D",
        "out",
        "--rules-dir",
        root,
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    // --rules-dir still refuses what is outside it.
    let o = a.rules(&[
        "check",
        "rules/uses_shared.dl",
        "--rules-dir",
        a.p("rules").to_str().unwrap(),
    ]);
    assert_refused(&o, &["`.include` refused"]);
}

#[test]
fn output_file_names_may_not_leave_the_out_folder() {
    let a = Area::new();
    let escapes = [
        (
            a.p("escaped.csv").display().to_string(),
            "is an absolute path",
        ),
        ("../escaped.csv".to_string(), "contains `..`"),
        ("link/escaped.csv".to_string(), "leaves the folder"),
    ];
    std::os::unix::fs::symlink(a.dir.path(), a.p("out/link")).unwrap();
    for (name, why) in escapes {
        write(
            &a.p("rules/out.dl"),
            &format!(".decl e(x: number)\ne(1).\n.output e(IO=file, filename=\"{name}\")\n"),
        );
        let o = a.rules(&["run", "rules/out.dl", "-D", "out"]);
        assert_refused(
            &o,
            &[
                "rules/out.dl:3",
                "`.output` of `e`",
                why,
                "it must stay in out",
                "--out",
            ],
        );
        assert!(!a.p("escaped.csv").exists(), "{name} was written outside");
    }
    // A plain relative name in a subfolder is fine.
    write(
        &a.p("rules/out.dl"),
        ".decl e(x: number)\ne(1).\n.output e(IO=file, filename=\"sub/e.csv\")\n",
    );
    let o = a.rules(&["run", "rules/out.dl", "-D", "out"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        std::fs::read_to_string(a.p("out/sub/e.csv")).unwrap(),
        "1\n"
    );
}

#[test]
fn input_file_names_may_not_leave_the_facts_folder() {
    let a = Area::new();
    std::os::unix::fs::symlink(a.p("secret.facts"), a.p("facts/linked.facts")).unwrap();
    let names = [
        (
            a.p("secret.facts").display().to_string(),
            "is an absolute path",
        ),
        ("../secret.facts".to_string(), "contains `..`"),
        ("linked.facts".to_string(), "leaves the folder"),
    ];
    for (name, why) in names {
        write(
            &a.p("rules/in.dl"),
            &format!(
                ".decl s(x: symbol)\n.input s(IO=file, filename=\"{name}\")\n.output s(IO=stdout)\n"
            ),
        );
        let o = a.rules(&["run", "rules/in.dl", "-F", "facts", "-D", "out"]);
        assert_refused(
            &o,
            &[
                "rules/in.dl:2",
                "`.input` of `s`",
                why,
                "it must stay in facts",
                "--facts",
            ],
        );
    }
}
