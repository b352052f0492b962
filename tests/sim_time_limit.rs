//! The bound on simulated time per wall (FRAMEWRIGHT_MAX_SIM_SECONDS_PER_WALL): a wall that
//! runs past it stops the simulation with an error naming the bound and how to raise it; a
//! value that is not a positive number is refused naming the variable. One test in its own
//! process: it sets the environment variable.

use framewright::cell::Cell;
use framewright::ifc::Model;
use framewright::sim::{ENV_MAX_SIM_SECONDS_PER_WALL, SimError, SimOptions, simulate};
use std::path::Path;

#[test]
fn a_wall_past_the_bound_stops_with_an_error_naming_it() {
    let model = Model::open(Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/tm1.ifc"))
        .expect("bundled model");
    let cell = Cell::load("study-abb").expect("cell");
    let options = SimOptions::default();

    // SAFETY: this file's only test; nothing else in the process reads the environment now.
    unsafe { std::env::set_var(ENV_MAX_SIM_SECONDS_PER_WALL, "5") };
    let err = match simulate(&model, &cell, &options) {
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

    unsafe { std::env::set_var(ENV_MAX_SIM_SECONDS_PER_WALL, "ten") };
    let err = simulate(&model, &cell, &options)
        .err()
        .expect("a bad bound is refused");
    assert!(matches!(err, SimError::BadLimit { .. }), "{err}");
    assert!(
        err.to_string()
            .contains("FRAMEWRIGHT_MAX_SIM_SECONDS_PER_WALL=\"ten\""),
        "{err}"
    );

    // Raised far enough, the wall finishes.
    unsafe { std::env::set_var(ENV_MAX_SIM_SECONDS_PER_WALL, "100000") };
    let sim = simulate(&model, &cell, &options).expect("the wall finishes under a raised bound");
    assert!(sim.records.iter().all(|r| r.nailing_end < 100_000.0));
    unsafe { std::env::remove_var(ENV_MAX_SIM_SECONDS_PER_WALL) };
}
