//! Where the workspace and Chromium are, and what the browser test lacks to run.

use std::path::{Path, PathBuf};
use std::process::Command;

pub(crate) fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").canonicalize().expect("the workspace root")
}

pub(crate) fn chromium() -> String {
    std::env::var("CHROMIUM").unwrap_or_else(|_| "/usr/bin/chromium".to_owned())
}

/// What is missing to run the browser test, with the command that installs each piece.
pub(crate) fn missing_prerequisites(root: &Path) -> Vec<String> {
    let runs = |program: &str, args: &[&str]| {
        Command::new(program).args(args).output().is_ok_and(|o| o.status.success())
    };
    let mut missing = Vec::new();
    let lock = std::fs::read_to_string(root.join("Cargo.lock")).expect("Cargo.lock");
    let wanted = lock
        .split("[[package]]")
        .find(|p| p.contains("\nname = \"wasm-bindgen\"\n"))
        .and_then(|p| p.lines().find_map(|l| l.strip_prefix("version = \"")))
        .map(|v| v.trim_end_matches('"').to_owned())
        .expect("wasm-bindgen in Cargo.lock");
    let have = Command::new("wasm-bindgen")
        .arg("--version")
        .output()
        .ok()
        .map(|o| String::from_utf8_lossy(&o.stdout).into_owned());
    if have.as_deref().is_none_or(|v| !v.contains(&wanted)) {
        missing.push(format!("wasm-bindgen {wanted} (cargo install wasm-bindgen-cli --version {wanted})"));
    }
    let targets = Command::new("rustup").args(["target", "list", "--installed"]).output();
    if targets
        .is_ok_and(|o| !String::from_utf8_lossy(&o.stdout).lines().any(|l| l == "wasm32-unknown-unknown"))
    {
        missing.push("the wasm32 target (rustup target add wasm32-unknown-unknown)".to_owned());
    }
    if !runs(&chromium(), &["--version"]) {
        missing.push(format!("chromium at {} (apt-get install chromium; or set CHROMIUM)", chromium()));
    }
    if !runs("node", &["--version"]) {
        missing.push("node (apt-get install nodejs npm)".to_owned());
    }
    if !root.join("web/tests/node_modules/playwright-core").is_dir() {
        missing.push("playwright-core (npm ci --prefix web/tests)".to_owned());
    }
    missing
}
