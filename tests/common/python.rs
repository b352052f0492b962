//! Python oracles (IfcOpenShell, IfcOpenShell's BCF reader, xmlschema): a test uses them when
//! installed and skips, saying what to install, when not (a failure under
//! `FRAMEWRIGHT_REQUIRE_ORACLES`, which `.ci/run` sets after installing them).
#![allow(dead_code)]

use std::process::Command;

/// `python3` when it imports every one of `modules`; otherwise None, after saying what is
/// skipped and which PyPI packages (`packages`) provide them.
pub fn python_with(modules: &[&str], packages: &str) -> Option<&'static str> {
    let script = modules
        .iter()
        .map(|m| format!("import {m}"))
        .collect::<Vec<_>>()
        .join("\n");
    let ok = Command::new("python3")
        .args(["-c", &script])
        .output()
        .is_ok_and(|o| o.status.success());
    if !ok {
        super::skip::missing_tool(
            &format!("python3 with {}", modules.join(", ")),
            &format!("python3 -m pip install {packages}"),
        );
    }
    ok.then_some("python3")
}

/// `python3` when it imports IfcOpenShell.
pub fn ifcopenshell() -> Option<&'static str> {
    python_with(&["ifcopenshell"], "ifcopenshell")
}
