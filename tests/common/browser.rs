//! A page as a person sees it: Debian's chromium, headless, loads it from `file://` (skipped,
//! saying so, when chromium is absent). WebGL runs on SwiftShader, chromium's software
//! renderer (opted into, so no deprecation warning reaches the console), and the page gets
//! ten seconds of virtual time to finish its scripts before the DOM is dumped or the
//! screenshot taken.

use std::path::Path;
use std::process::Command;

pub fn chromium() -> Option<&'static str> {
    for c in ["chromium", "chromium-browser"] {
        if Command::new(c)
            .arg("--version")
            .output()
            .is_ok_and(|o| o.status.success())
        {
            return Some(c);
        }
    }
    super::skip::missing_tool("chromium", "apt-get install chromium");
    None
}

/// Loads a page in headless chromium: (rendered DOM, browser log), and a screenshot.
pub fn browse(browser: &str, page: &Path, screenshot: &Path) -> (String, String) {
    let profile = tempfile::tempdir().unwrap();
    let common = |cmd: &mut Command| {
        cmd.args([
            "--headless",
            "--no-sandbox",
            "--use-angle=swiftshader",
            "--enable-unsafe-swiftshader",
            "--virtual-time-budget=10000",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--enable-logging=stderr",
            "--v=0",
        ])
        .arg(format!("--user-data-dir={}", profile.path().display()));
    };
    let url = format!("file://{}", page.display());
    let mut dump = Command::new(browser);
    common(&mut dump);
    let out = dump
        .arg("--dump-dom")
        .arg(&url)
        .output()
        .expect("chromium runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut shot = Command::new(browser);
    common(&mut shot);
    let s = shot
        .arg(format!("--screenshot={}", screenshot.display()))
        .arg("--window-size=1000,2600")
        .arg(&url)
        .output()
        .expect("chromium runs");
    assert!(s.status.success());
    assert!(screenshot.exists(), "no screenshot");
    (
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Console messages the page logged (chromium writes them as `CONSOLE(…)` lines).
pub fn console_errors(log: &str) -> Vec<&str> {
    log.lines().filter(|l| l.contains("CONSOLE")).collect()
}
