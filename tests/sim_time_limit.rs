//! The bound on simulated time per wall: a wall that runs past it stops the simulation with an
//! error naming the bound and how to raise it (`SimOptions::max_seconds_per_wall`, which the
//! CLI reads from FRAMEWRIGHT_MAX_SIM_SECONDS_PER_WALL); a value that is not a positive
//! number is refused naming the variable.

use framewright::cell::Cell;
use framewright::ifc::Model;
use framewright::pipeline::simulate;
use framewright::sim::{SimError, SimOptions};
use std::path::{Path, PathBuf};
use std::process::Command;

fn tm1() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/tm1.ifc")
}

#[test]
fn a_wall_past_the_bound_stops_with_an_error_naming_it() {
    let model = Model::open(tm1()).expect("bundled model");
    let cell = Cell::load("study-abb").expect("cell");
    let bounded = |seconds: f64| SimOptions {
        max_seconds_per_wall: seconds,
        ..SimOptions::default()
    };
    let err = match simulate(&model, &cell, &bounded(5.0)) {
        Err(e) => e,
        Ok(_) => panic!("a 5 s bound stops TM1 (its wall takes minutes)"),
    };
    let SimError::TimeLimit { limit, reached, .. } = &err else {
        panic!("expected the time bound, got {err}");
    };
    assert_eq!(*limit, 5.0);
    assert!(*reached > 5.0, "stopped at {reached} s");
    let message = err.to_string();
    assert!(
        message.contains("5 s of simulated time per wall")
            && message.contains("FRAMEWRIGHT_MAX_SIM_SECONDS_PER_WALL=SECONDS"),
        "{message}"
    );
    for bad in [0.0, -1.0, f64::NAN] {
        let err = simulate(&model, &cell, &bounded(bad)).err();
        assert!(matches!(err, Some(SimError::Option(_))), "{bad}: {err:?}");
    }
    // Raised far enough, the wall finishes.
    let sim = simulate(&model, &cell, &bounded(100_000.0))
        .expect("the wall finishes under a raised bound");
    assert!(sim.records.iter().all(|r| r.nailing_end < 100_000.0));
}

#[test]
fn the_cli_takes_the_bound_from_the_environment() {
    let run = |value: &str| {
        Command::new(env!("CARGO_BIN_EXE_framewright"))
            .args(["simulate", "--no-cache"])
            .arg(tm1())
            .env("FRAMEWRIGHT_MAX_SIM_SECONDS_PER_WALL", value)
            .output()
            .expect("runs")
    };
    let o = run("ten");
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("FRAMEWRIGHT_MAX_SIM_SECONDS_PER_WALL=\"ten\""),
        "{err}"
    );
    let o = run("5");
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("within the bound of 5 s"),
        "the CLI passes the bound to the run: {err}"
    );
}
