//! Fuzzing the scene parser and validator with proptest: generated and mutated scene files
//! (random bytes, truncations, type swaps, huge and tiny numbers, NaN spellings, deep nesting,
//! unknown keys). Nothing may panic, and every rejection must name the file and, where the
//! error is about one, the field (or the line and column of the offending text).
//!
//! `FUZZ_CASES` sets the number of files (default 100,000, which runs in a few seconds in a
//! release-optimised dependency build; see the README's test section).

use illum_scene::{Scene, SceneError};
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};

const FILE: &str = "fuzz/scene.toml";

/// The seed files every mutation starts from: the repository's scenes.
fn seeds() -> Vec<String> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut seeds: Vec<String> = std::fs::read_dir(&dir)
        .expect("scenes/")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .map(|p| std::fs::read_to_string(p).expect("readable"))
        .collect();
    seeds.sort();
    assert!(seeds.len() >= 3, "expected the scene files in {}", dir.display());
    seeds
}

/// Values that stress a number or a type: extremes, NaN spellings, other TOML types.
const TOKENS: &[&str] = &[
    "nan",
    "+nan",
    "-nan",
    "inf",
    "-inf",
    "+inf",
    "NaN",
    "\"nan\"",
    "1e308",
    "-1e308",
    "1.8e308",
    "1e-320",
    "5e-324",
    "0",
    "-0.0",
    "0.0",
    "3.4028235e38",
    "3.5e38",
    "1e39",
    "-3.4028235e38",
    "1e-45",
    "1e-38",
    "9223372036854775807",
    "-9223372036854775808",
    "99999999999999999999",
    "4294967295",
    "4294967296",
    "-1",
    "1",
    "0x10",
    "0b11",
    "1_000",
    "\"16\"",
    "true",
    "[]",
    "[1.0]",
    "[1.0, 2.0]",
    "[1e39, 0, nan]",
    "[[1.0, 2.0, 3.0]]",
    "{}",
    "{ x = 1 }",
    "1979-05-27",
    "'''x'''",
    "\"\"",
    "\"unbounded\"",
    "\"\\u0000\"",
];

/// One edit of a scene file's text.
#[derive(Clone, Debug)]
enum Mutation {
    /// Keep the first `at` bytes (any position, on a char boundary at or below it).
    Truncate(usize),
    /// Replace the n-th number literal by a token.
    ReplaceNumber(usize, &'static str),
    /// Replace the value of the n-th `key = value` line by a token (a type swap).
    ReplaceValue(usize, &'static str),
    /// Insert a line at line n.
    InsertLine(usize, String),
    /// Delete line n.
    DeleteLine(usize),
    /// Duplicate line n.
    DuplicateLine(usize),
    /// Overwrite byte n with a random byte (may break UTF-8: the file is read lossily then).
    FlipByte(usize, u8),
}

fn extra_line() -> impl Strategy<Value = String> {
    prop_oneof![
        "[a-z_]{1,12} = [0-9.e+-]{1,8}".prop_map(|s| s),
        (1usize..=3000).prop_map(|depth| format!("deep = {}1{}", "[".repeat(depth), "]".repeat(depth))),
        (1usize..=3000)
            .prop_map(|depth| format!("deep = {}", "{ a = ".repeat(depth) + "1" + &" }".repeat(depth))),
        "\\[[a-z_.]{1,16}\\]".prop_map(|s| s),
        "\\[\\[[a-z_]{1,10}\\]\\]".prop_map(|s| s),
        proptest::sample::select(TOKENS).prop_map(|t| format!("spp = {t}")),
        "\\PC{0,40}".prop_map(|s| s),
    ]
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let token = proptest::sample::select(TOKENS);
    prop_oneof![
        (0usize..6000).prop_map(Mutation::Truncate),
        (0usize..200, token.clone()).prop_map(|(n, t)| Mutation::ReplaceNumber(n, t)),
        (0usize..120, token).prop_map(|(n, t)| Mutation::ReplaceValue(n, t)),
        (0usize..150, extra_line()).prop_map(|(n, l)| Mutation::InsertLine(n, l)),
        (0usize..150).prop_map(Mutation::DeleteLine),
        (0usize..150).prop_map(Mutation::DuplicateLine),
        (0usize..6000, any::<u8>()).prop_map(|(n, b)| Mutation::FlipByte(n, b)),
    ]
}

fn apply(text: &str, m: &Mutation) -> String {
    let lines: Vec<&str> = text.lines().collect();
    let line = |n: usize| n % lines.len().max(1);
    match m {
        Mutation::Truncate(at) => {
            let mut at = (*at).min(text.len());
            while !text.is_char_boundary(at) {
                at -= 1;
            }
            text[..at].to_owned()
        }
        Mutation::ReplaceNumber(n, token) => {
            let numbers: Vec<(usize, usize)> = number_spans(text);
            match numbers.get(n % numbers.len().max(1)) {
                Some(&(a, b)) => format!("{}{}{}", &text[..a], token, &text[b..]),
                None => text.to_owned(),
            }
        }
        Mutation::ReplaceValue(n, token) => {
            let keyed: Vec<usize> = (0..lines.len()).filter(|&i| lines[i].contains(" = ")).collect();
            let mut out: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
            if let Some(&i) = keyed.get(n % keyed.len().max(1)) {
                let key = lines[i].split(" = ").next().unwrap_or_default();
                out[i] = format!("{key} = {token}");
            }
            out.join("\n")
        }
        Mutation::InsertLine(n, new) => {
            let mut out: Vec<&str> = lines.clone();
            out.insert(line(*n).min(out.len()), new);
            out.join("\n")
        }
        Mutation::DeleteLine(n) => {
            let mut out = lines.clone();
            if !out.is_empty() {
                out.remove(line(*n));
            }
            out.join("\n")
        }
        Mutation::DuplicateLine(n) => {
            let mut out = lines.clone();
            if !out.is_empty() {
                let l = out[line(*n)];
                out.insert(line(*n), l);
            }
            out.join("\n")
        }
        Mutation::FlipByte(n, byte) => {
            let mut bytes = text.as_bytes().to_vec();
            if !bytes.is_empty() {
                let i = n % bytes.len();
                bytes[i] = *byte;
            }
            String::from_utf8_lossy(&bytes).into_owned()
        }
    }
}

/// Byte spans of the number literals of `text` (a digit run with its sign, point and exponent).
fn number_spans(text: &str) -> Vec<(usize, usize)> {
    let bytes = text.as_bytes();
    let mut spans = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i].is_ascii_digit()
            && (i == 0 || !bytes[i - 1].is_ascii_alphabetic() && bytes[i - 1] != b'_')
        {
            let start = if i > 0 && bytes[i - 1] == b'-' { i - 1 } else { i };
            let mut end = i;
            while end < bytes.len() && (bytes[end].is_ascii_digit() || b".eE+-_".contains(&bytes[end])) {
                end += 1;
            }
            spans.push((start, end));
            i = end;
        } else {
            i += 1;
        }
    }
    spans
}

/// The property: parsing `text` returns, and an error names the file and its field or place.
fn check(text: &str) -> Result<(), TestCaseError> {
    match Scene::from_toml_str(text, FILE) {
        Ok(scene) => {
            // A scene that validates must be usable: finite camera, non-empty resolution.
            prop_assert!(scene.camera.width >= 1 && scene.camera.height >= 1);
            prop_assert!(scene.camera.eye.is_finite() && scene.camera.vfov_deg.is_finite());
        }
        Err(error) => {
            let shown = error.to_string();
            prop_assert!(shown.starts_with(FILE), "does not name the file: {shown}");
            match &error {
                SceneError::Invalid { field, value, .. } => {
                    prop_assert!(!field.is_empty() && shown.contains(field.as_str()), "no field: {shown}");
                    prop_assert!(shown.contains(value.as_str()));
                }
                SceneError::Syntax { line, column, message, .. } => {
                    prop_assert!(*line >= 1 && *column >= 1 && !message.is_empty(), "{shown}");
                    prop_assert!(shown.starts_with(&format!("{FILE}:{line}:{column}: ")), "{shown}");
                }
                SceneError::Unsupported { place, .. } => prop_assert!(!place.is_empty(), "{shown}"),
                SceneError::Io { .. } => prop_assert!(false, "no file is read here: {shown}"),
            }
        }
    }
    Ok(())
}

fn cases() -> u32 {
    std::env::var("FUZZ_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(100_000)
}

/// Runs `cases` cases of `strategy` against [`check`], without saving failures to disk (CI has
/// nowhere to keep them; a failure prints its minimal input).
fn fuzz<S: Strategy>(cases: u32, strategy: S, text: impl Fn(&S::Value) -> String) -> u32
where
    S::Value: std::fmt::Debug,
{
    let config = Config { cases, failure_persistence: None, max_shrink_iters: 2000, ..Config::default() };
    let mut runner = TestRunner::new(config);
    let started = std::time::Instant::now();
    runner.run(&strategy, |value| check(&text(&value))).unwrap_or_else(|e| panic!("{e}"));
    let seconds = started.elapsed().as_secs_f64();
    println!("{cases} cases in {seconds:.2} s ({:.0} per second)", f64::from(cases) / seconds);
    cases
}

#[test]
fn mutated_scene_files_never_panic_and_every_rejection_names_file_and_field() {
    let seeds = seeds();
    let n = seeds.len();
    // Most of the budget: one to four mutations of a real scene file.
    let strategy = (0..n, proptest::collection::vec(mutation(), 1..=4));
    fuzz(cases() * 4 / 5, strategy, |(seed, mutations)| {
        mutations.iter().fold(seeds[*seed].clone(), |text, m| apply(&text, m))
    });
}

#[test]
fn random_bytes_and_random_toml_never_panic() {
    let strategy = prop_oneof![
        proptest::collection::vec(any::<u8>(), 0..400).prop_map(|b| String::from_utf8_lossy(&b).into_owned()),
        proptest::collection::vec(extra_line(), 0..12).prop_map(|lines| lines.join("\n")),
    ];
    fuzz(cases() / 5, strategy, |text| text.clone());
}

#[test]
fn deep_nesting_is_an_error_not_a_stack_overflow() {
    for depth in [100, 10_000, 100_000] {
        for text in [
            format!("x = {}1{}", "[".repeat(depth), "]".repeat(depth)),
            format!("x = {}1{}", "{ a = ".repeat(depth), " }".repeat(depth)),
        ] {
            let err = Scene::from_toml_str(&text, FILE).expect_err("not a scene");
            assert!(err.to_string().starts_with(FILE), "{err}");
        }
    }
}
