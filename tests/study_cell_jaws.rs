//! The study's cells with a real wall's pieces: a piece whose jaws would meet a placed
//! neighbour (closed on it, or opening to let it go) is refused when its framing is planned,
//! before the arm moves, instead of being driven into the neighbour.

mod common;

use serde_json::Value;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).to_path_buf()
}

/// The bundled wall with a door and a window: king studs set face to face against their
/// jacks.
fn wall() -> PathBuf {
    root().join("tests/fixtures/synth_wall_door_window_in.ifc")
}

fn simulate(model: &Path, cell: &str) -> Value {
    let out = common::framewright_ok(&[
        "simulate",
        model.to_str().unwrap(),
        "--cell",
        cell,
        "--json",
        "--no-cache",
    ]);
    serde_json::from_str(&out).expect("JSON")
}

/// Every framing reason of every element, with the element's id and role.
fn reasons(sim: &Value) -> Vec<(String, String, String)> {
    sim["elements"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|e| {
            e["framing"]["reasons"]
                .as_array()
                .unwrap()
                .iter()
                .map(move |r| {
                    (
                        e["id"].as_str().unwrap().to_string(),
                        e["role"].as_str().unwrap_or("").to_string(),
                        r["message"].as_str().unwrap().to_string(),
                    )
                })
        })
        .collect()
}

#[test]
fn jaws_that_would_meet_a_placed_neighbour_are_refused_at_the_plan_not_during_the_place() {
    let model = wall();
    for cell in ["study-abb", "study-kuka"] {
        let all = reasons(&simulate(&model, cell));
        // No finger is driven into anything while the arm places a piece.
        let touched: Vec<_> = all
            .iter()
            .filter(|(_, _, m)| m.contains("finger touched") && m.contains("during place"))
            .collect();
        assert!(touched.is_empty(), "{cell}: {touched:?}");
        // On the ABB the king studs beside their jacks are within reach: they are refused
        // for the finger, naming the neighbour.
        if cell == "study-abb" {
            let refused: Vec<_> = all
                .iter()
                .filter(|(_, _, m)| {
                    m.contains("place pose: every solution collides: tool gripper_")
                })
                .collect();
            assert!(
                refused
                    .iter()
                    .any(|(_, role, m)| role == "king_stud" && m.contains("finger with piece")),
                "{cell}: {all:?}"
            );
        }
    }
}
