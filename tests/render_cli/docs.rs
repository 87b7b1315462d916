//! Every example's `--help`, and the README and docs naming only examples, flags and pictures
//! that exist.

use super::*;

/// Every example of `examples/`: a `NAME.rs` file or a `NAME/main.rs` folder.
fn example_names() -> Vec<String> {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples");
    let mut names: Vec<String> = std::fs::read_dir(&folder)
        .expect("the examples folder")
        .map(|entry| entry.expect("an entry").path())
        .filter_map(|path| match path.extension() {
            Some(ext) if ext == "rs" => path.file_stem().map(|s| s.to_string_lossy().into_owned()),
            None if path.join("main.rs").exists() => {
                path.file_name().map(|s| s.to_string_lossy().into_owned())
            }
            _ => None,
        })
        .collect();
    names.sort();
    names
}

#[test]
fn every_examples_help_says_what_it_does_and_documents_each_flag() {
    let names = example_names();
    assert!(names.len() >= 8 && names.iter().any(|n| n == "ladder"), "{names:?}");
    for name in &names {
        let binary = example_binary(name);
        assert!(binary.exists(), "{} is missing (cargo test builds the examples)", binary.display());
        let out = Command::new(&binary).arg("--help").output().expect("runs");
        assert!(out.status.success(), "{name} --help failed");
        let help = text(&out.stdout);
        let first = help.lines().next().unwrap_or_default();
        assert!(!first.starts_with("Usage"), "{name} --help has no description line:\n{help}");
        // Every flag and argument has a description: after its name on the same line, or (when
        // clap wraps a long help) on the next, more indented line.
        let lines: Vec<&str> = help.lines().collect();
        let mut section = "";
        for (i, line) in lines.iter().enumerate() {
            if line.ends_with(':') && !line.starts_with(' ') {
                section = line;
                continue;
            }
            let is_entry = line.starts_with("  ") && line.trim_start().starts_with(['-', '[', '<']);
            if (section == "Options:" || section == "Arguments:") && is_entry {
                let same_line = line.trim().split("  ").filter(|part| !part.trim().is_empty()).count() >= 2;
                let next = lines.get(i + 1).copied().unwrap_or_default();
                let indent = |l: &str| l.len() - l.trim_start().len();
                let next_line = !next.trim().is_empty()
                    && indent(next) > indent(line)
                    && !next.trim_start().starts_with('-');
                assert!(same_line || next_line, "{name}: undocumented: {line:?}\n{help}");
            }
        }
    }
    // The convergence tool sets spp (--spp-list) and sampling (it measures both) itself: its
    // help must not offer flags it would refuse.
    let out = Command::new(example_binary("convergence")).arg("--help").output().expect("runs");
    let help = text(&out.stdout);
    for flag in ["--spp ", "--sampling"] {
        assert!(!help.contains(flag), "convergence --help offers {flag}:\n{help}");
    }
    assert!(help.contains("--spp-list") && help.contains("--bounces"), "{help}");
}

/// The benchmarks refuse repetition counts that measure nothing (0) or would run for days, with
/// the flag, the value and the range, before touching the GPU.
#[test]
fn benchmarks_refuse_absurd_repetition_counts() {
    let ranges = [("--runs", "1..=1000"), ("--frames", "1..=100000"), ("--warmup", "0..=10000")];
    let cases = [
        "bench --runs 0",
        "bench --runs 1000000",
        "raster_bench --frames 0",
        "raster_bench --frames 100000000",
        "raster_bench --warmup 20000",
    ];
    for case in cases {
        let words: Vec<&str> = case.split(' ').collect();
        let out = Command::new(example_binary(words[0])).args(&words[1..]).output().expect("runs");
        let range = ranges.iter().find(|(flag, _)| *flag == words[1]).map(|(_, range)| *range);
        assert_refused(&out, case, &[words[1], words[2], range.expect("a range per flag")]);
    }
}

/// Every picture the README and the docs show exists, every `--example NAME` they name is an
/// example, and every flag on a line that runs an example is one that example's `--help` lists.
/// (The numbers they quote are re-measured by `scripts/readme-figures.sh`; timings cannot be
/// asserted.)
#[test]
fn the_readme_shows_only_pictures_examples_and_flags_that_exist() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut pages = vec![(root.join("README.md"), "](docs/images/", "docs/images/")];
    for entry in std::fs::read_dir(root.join("docs")).expect("docs/") {
        let path = entry.expect("an entry").path();
        if path.extension().is_some_and(|e| e == "md") {
            pages.push((path, "](images/", "docs/images/"));
        }
    }
    let mut text_of_all = String::new();
    for (page, link, folder) in &pages {
        let content = std::fs::read_to_string(page).expect("a page");
        for (i, _) in content.match_indices(link) {
            let rest = &content[i + link.len()..];
            let name = &rest[..rest.find(')').expect("closing parenthesis")];
            assert!(
                root.join(folder).join(name).exists(),
                "{} shows {name}, which does not exist",
                page.display()
            );
        }
        text_of_all.push_str(&content);
        text_of_all.push('\n');
    }
    let readme = text_of_all;
    let facade_examples = example_names();
    let mut checked = 0;
    for line in readme.lines() {
        let Some(at) = line.find("--example ") else { continue };
        let name: String = line[at + "--example ".len()..]
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        if !facade_examples.contains(&name) {
            // Another crate's example (`-p illum-oracle --example NAME`): it must exist.
            let elsewhere = std::fs::read_dir(root.join("crates"))
                .expect("crates/")
                .any(|c| c.expect("an entry").path().join("examples").join(format!("{name}.rs")).exists());
            assert!(elsewhere, "the docs name --example {name}, which is no example");
            continue;
        }
        let help = Command::new(example_binary(&name)).arg("--help").output().expect("the example starts");
        assert!(help.status.success(), "README names --example {name}, which has no working --help");
        let help = text(&help.stdout);
        // The flags after the example's name, as the line spells them (`--spp N`, `[--look ...]`).
        for word in line[at..].split(|c: char| c.is_whitespace() || "[]`|=,()".contains(c)).skip(2) {
            if let Some(flag) =
                word.strip_prefix("--").filter(|f| f.chars().all(|c| c.is_ascii_lowercase() || c == '-'))
            {
                if flag.is_empty() || flag == "release" || flag == "example" {
                    continue;
                }
                assert!(
                    help.contains(&format!("--{flag}")),
                    "README runs `{name}` with --{flag}, which its --help lacks"
                );
                checked += 1;
            }
        }
    }
    assert!(checked > 20, "only {checked} flags found in the example lines of the README and docs");
}

/// The README's set-up line installs exactly the packages `scripts/setup.sh` (what `.ci/run`
/// runs) installs for the default test run, so that the two cannot drift apart.
#[test]
fn the_readmes_setup_line_is_the_setup_scripts_list() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let readme = std::fs::read_to_string(root.join("README.md")).expect("README.md");
    let script = std::fs::read_to_string(root.join("scripts/setup.sh")).expect("scripts/setup.sh");
    let base = script
        .lines()
        .find_map(|l| l.strip_prefix("BASE_PACKAGES=\""))
        .and_then(|l| l.strip_suffix('"'))
        .expect("BASE_PACKAGES in scripts/setup.sh");
    let line = format!("sudo apt-get install -y {base}");
    assert!(readme.contains(&format!("```sh\n{line}\n```")), "the README's set-up line is not `{line}`");
    let ci = std::fs::read_to_string(root.join(".ci/run")).expect(".ci/run");
    assert!(ci.contains("scripts/setup.sh"), ".ci/run does not install through scripts/setup.sh");
}
