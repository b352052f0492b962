//! Inputs the fuzzer (`fuzz/run.sh`) found to crash or hang a reader, replayed through the
//! same calls as the fuzz targets (`fuzz/src/lib.rs`, included here so both run one code).
//! Each lives in `tests/fixtures/fuzz/<target>/` (every target keeps at least one input); every
//! one must now return (an error or a model) without a panic, well inside the fuzzer's
//! one-second limit, and the hand-kept ones get the answer named here. Inputs that are large but
//! regular (deep nesting) are generated here instead, with the message they must now get.

#[path = "../fuzz/src/lib.rs"]
mod targets;

use framewright::cell::{Robot, RobotMeta};
use framewright::logic::Program;
use std::path::Path;
use std::sync::mpsc;
use std::time::Duration;

/// Far above the fuzzer's 1 s per input, so a loaded machine does not fail the test; an input
/// that hangs again still does.
const HANG: Duration = Duration::from_secs(20);

/// Replays every kept input of `target`; a target must keep at least one.
fn replay(target: &str, run: fn(&[u8])) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/fuzz")
        .join(target);
    let entries = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}: no kept input to replay", dir.display()));
    let mut files: Vec<_> = entries
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_none_or(|e| e != "md"))
        .collect();
    files.sort();
    for file in &files {
        let data = std::fs::read(file).unwrap();
        let (done, finished) = mpsc::channel();
        let name = file.display().to_string();
        let worker = std::thread::Builder::new()
            .name(name.clone())
            .stack_size(8 << 20)
            .spawn(move || {
                run(&data);
                let _ = done.send(());
            })
            .unwrap();
        match finished.recv_timeout(HANG) {
            Ok(()) => worker.join().unwrap(),
            Err(mpsc::RecvTimeoutError::Timeout) => panic!("{name}: still running after {HANG:?}"),
            Err(mpsc::RecvTimeoutError::Disconnected) => panic!("{name}: panicked (see above)"),
        }
    }
    assert!(
        !files.is_empty(),
        "{}: no kept input to replay",
        dir.display()
    );
}

/// A kept input's text, without the byte that picks the reader for `cell_toml`.
fn kept(path: &str) -> (String, String) {
    let file = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/fuzz")
        .join(path);
    let bytes = std::fs::read(&file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    (
        file.display().to_string(),
        String::from_utf8(bytes).unwrap(),
    )
}

// The kept inputs of the targets where no fuzz run found a crash: one of each kind of hostile
// input the reader must refuse or read, with what it must say. The replays above check that
// none panics or hangs; these check that each gets its answer.
#[test]
fn kept_ifc_inputs_get_their_answers() {
    use framewright::ifc::Model;
    use framewright::step::ReadOptions;
    for (name, says) in [
        ("truncated-inside-a-string.ifc", Some("looks truncated")),
        (
            "placement-cycle.ifc",
            Some("placement cycle #1 -> #2 -> #1"),
        ),
        (
            "reference-to-an-undefined-entity.ifc",
            Some("#3 refers to #98, which is not defined in the file"),
        ),
        // Read, holding nothing to frame.
        ("list-nested-5000-deep.ifc", None),
        ("numbers-out-of-range.ifc", None),
    ] {
        let (path, text) = kept(&format!("ifc/{name}"));
        let answer = Model::from_bytes(&path, text.into_bytes(), &ReadOptions::default());
        match (answer, says) {
            (Err(e), Some(says)) => assert!(e.to_string().contains(says), "{path}: {e}"),
            (Ok(model), Some(says)) => {
                let warnings: Vec<String> =
                    model.warnings.iter().map(|w| w.message.clone()).collect();
                assert!(
                    warnings.iter().any(|w| w.contains(says)),
                    "{path}: {warnings:?}"
                );
            }
            (Ok(model), None) => assert!(model.pieces().is_empty(), "{path}"),
            (Err(e), None) => panic!("{path}: refused: {e}"),
        }
    }
}

#[test]
fn kept_cell_tool_and_robot_inputs_are_refused_naming_the_key() {
    use framewright::cell::{Cell, Tool};
    for (name, says) in [
        (
            "cell-nan-belt-speed.toml",
            "key `conveyor2.speed`: expected a belt speed",
        ),
        ("tool-negative-part-mass.toml", "mass"),
        ("robot-infinite-reach.toml", "reach"),
    ] {
        let (path, text) = kept(&format!("cell_toml/{name}"));
        let (reader, text) = text.split_at(1);
        let p = Path::new(&path);
        let message = match reader {
            "0" => Cell::from_toml(p, text).err().map(|e| e.to_string()),
            "1" => Tool::parse(p, text).err().map(|e| e.to_string()),
            _ => RobotMeta::parse(p, text).err().map(|e| e.to_string()),
        }
        .unwrap_or_else(|| panic!("{path}: accepted"));
        assert!(message.contains(says), "{path}: {message}");
    }
}

#[test]
fn kept_urdf_inputs_are_refused_saying_why() {
    for (name, says) in [
        ("joint-cycle.urdf", "expected one root link"),
        ("nan-origin-zero-axis-inverted-limits.urdf", "joint `j1`"),
    ] {
        let (path, text) = kept(&format!("urdf/{name}"));
        let e = Robot::from_urdf_str(Path::new(&path), &text, RobotMeta::default())
            .err()
            .unwrap_or_else(|| panic!("{path}: accepted"));
        assert!(e.to_string().contains(says), "{path}: {e}");
    }
}

#[test]
fn ifc_inputs_no_longer_crash() {
    replay("ifc", targets::ifc);
}

#[test]
fn rules_front_inputs_no_longer_crash() {
    replay("rules_front", targets::rules_front);
}

#[test]
fn rules_run_inputs_no_longer_crash() {
    replay("rules_run", targets::rules_run);
}

#[test]
fn cell_toml_inputs_no_longer_crash() {
    replay("cell_toml", targets::cell_toml);
}

#[test]
fn urdf_inputs_no_longer_crash() {
    replay("urdf", targets::urdf);
}

/// The message `text` gets from the rule front end, which must refuse it (on a thread with a
/// test's small stack, where the recursion overflowed first).
fn refused(text: String) -> String {
    std::thread::Builder::new()
        .stack_size(2 << 20)
        .spawn(move || match Program::parse_str("deep.dl", &text) {
            Ok(_) => panic!("accepted"),
            Err(d) => d.to_string(),
        })
        .unwrap()
        .join()
        .expect("the front end overflowed its stack or panicked")
}

// Found by hand after the fuzz runs: AFL's mutations rarely build nesting thousands deep.
// Before the bound these overflowed the stack in the parser (parentheses, `!`) or in the
// recursion over the expression tree (`-` and `+` chains).
// (`-` nests: each one is a level, so the nesting bound stops it first.)
#[test]
fn deeply_nested_rules_get_a_message_not_a_stack_overflow() {
    let head = ".decl a(x: number)\na(x) :- x = ";
    let n = 50_000;
    for (text, says) in [
        (
            format!("{head}{}1{}.\n", "(".repeat(n), ")".repeat(n)),
            "nest more than 100 levels",
        ),
        (
            format!("{head}{}1.\n", "-".repeat(n)),
            "nest more than 100 levels",
        ),
        (
            format!("{head}1{}.\n", "+1".repeat(n)),
            "more than 1000 operators",
        ),
        (
            format!(".decl a(x: number)\na(1) :- {}a(1).\n", "!".repeat(n)),
            "nest more than 100 levels",
        ),
    ] {
        let message = refused(text);
        assert!(message.contains(says), "{message}");
        assert!(
            message.contains("deep.dl:2:"),
            "names file and line: {message}"
        );
    }
    // Ordinary depth and length still read.
    let fine = format!(
        "{head}{}1{} + {}.\n",
        "(".repeat(50),
        ")".repeat(50),
        vec!["1"; 500].join(" + ")
    );
    Program::parse_str("fine.dl", &fine).unwrap();
}

// Found by libFuzzer (rules_front, kept in tests/fixtures/fuzz/rules_front/): a `(` is read
// first as a parenthesised body, then as an expression, and aggregates put bodies back inside
// expressions, so each `(sum y : {` level doubled the work: 20 levels took 1.3 s and the
// nesting bound's 33 would have taken days. Now every level is read once per depth.
#[test]
fn nested_aggregate_groups_are_read_in_linear_time() {
    let head = ".decl a(x: number)\n.decl r(x: number)\na(x) :- r(x), ";
    for levels in [20, 33, 99, 2_000] {
        let text = format!(
            "{head}{}x{}.\n",
            "(sum y : {".repeat(levels),
            "}".repeat(levels)
        );
        let (done, finished) = mpsc::channel();
        std::thread::Builder::new()
            .stack_size(8 << 20)
            .spawn(move || {
                let _ = done.send(
                    Program::parse_str("agg.dl", &text)
                        .err()
                        .map(|e| e.to_string()),
                );
            })
            .unwrap();
        let message = finished
            .recv_timeout(Duration::from_secs(10))
            .unwrap_or_else(|_| panic!("{levels} nested aggregate groups still parsing after 10 s"))
            .expect("an unclosed group is an error");
        assert!(message.contains("agg.dl:3:"), "{message}");
    }
    // A valid nesting of groups and aggregates reads as before.
    let ok = ".decl a(x: number)\n.decl r(x: number)\na(x) :- r(x), ((r(x), (x < 3 ; x > 5))), x = (sum y : { r(y), ((y > 1)) }).\n";
    Program::parse_str("ok.dl", ok).unwrap();
}

// 200,000 nested elements took about a minute in the URDF parser (quadratic in depth).
#[test]
fn deeply_nested_urdf_is_refused_before_parsing() {
    let n = 200_000;
    let text = format!(
        "<robot name=\"r\">\n<link name=\"a\"/>\n{}{}</robot>",
        "<a>".repeat(n),
        "</a>".repeat(n)
    );
    let e = Robot::from_urdf_str(Path::new("deep.urdf"), &text, RobotMeta::default())
        .expect_err("refused");
    let message = e.to_string();
    assert!(
        message.contains("deep.urdf")
            && message.contains("line 3")
            && message.contains("more than 64 levels"),
        "{message}"
    );
}

/// The error a program gets under the fuzz targets' limits, on a thread bounded by `HANG`.
fn stopped_under_run_limits(text: &'static str) -> String {
    use framewright::logic::{Engine, Options};
    let (done, finished) = mpsc::channel();
    std::thread::spawn(move || {
        let program = std::sync::Arc::new(Program::parse_str("runaway.dl", text).unwrap());
        let mut engine = Engine::new(
            program,
            Options {
                provenance: true,
                limits: targets::RUN_LIMITS,
            },
        );
        let _ = done.send(engine.run().map(|_| ()).map_err(|e| e.to_string()));
    });
    match finished.recv_timeout(HANG) {
        Ok(Err(message)) => message,
        Ok(Ok(())) => panic!("{text}: ran to its end under the limits"),
        Err(e) => panic!("{text}: {e:?} after {HANG:?}"),
    }
}

// Shapes that kept the interpreter busy far past the fuzzer's second (or its memory) while
// the tuple and iteration limits held: each now stops at a limit that names it.
#[test]
fn runaway_shapes_stop_at_a_limit_under_the_fuzz_bounds() {
    let numbers = ".decl a(x: number)\na(0).\na(x + 1) :- a(x), x < 149.\n";
    for (rest, says) in [
        // Work without output: 150^3 visits for 150 tuples.
        (
            ".decl c(x: number)\nc(x) :- a(x), a(y), a(z), y != z.\n",
            "body tuples visited",
        ),
        // 22,500 new tuples in one evaluation of one rule.
        (
            ".decl b(x: number, y: number)\nb(x, y) :- a(x), a(y).\n",
            "more than 20000 tuples",
        ),
        // A string doubling every iteration.
        (
            ".decl s(x: symbol)\ns(\"ab\").\ns(cat(x, x)) :- s(x).\n",
            "more than the limit of 1048576 bytes",
        ),
    ] {
        let text: &'static str = format!("{numbers}{rest}").leak();
        let message = stopped_under_run_limits(text);
        assert!(message.contains(says), "{text}\n{message}");
        assert!(message.contains("runaway.dl:"), "names the rule: {message}");
    }
}
