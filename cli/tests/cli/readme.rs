//! The README's commands work out of the box: each `haarshift` command of its first code block
//! runs, as written, in a copy of the repository's files (with `results/` as committed), twice,
//! succeeds both times, prints its table and leaves `results/` alone; and every `haarshift`
//! line of its other `sh` blocks runs in order from the root of a copy and succeeds (the few
//! that take minutes as written at the smaller sizes of [`SMALLER`]), and every `cmp A B` line
//! among them finds the two files it names equal, byte for byte; `relight view`, a server, on a
//! free port until it serves its page; and every `cargo run ... --example NAME -- ARGS` line
//! runs that example's program, as `cargo test` built it, with `/tmp/` outputs in a temporary
//! directory.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use crate::common::repository;

const CARGO_RUN: &str = "cargo run --release -p haarshift-cli -- ";

/// The `haarshift` arguments of every `cargo run` line in the README's first code block.
fn opening_commands(readme: &str) -> Vec<Vec<String>> {
    let block = readme
        .split("```")
        .nth(1)
        .expect("the README has a code block");
    block
        .lines()
        .filter_map(|line| line.trim().strip_prefix(CARGO_RUN))
        .map(|args| args.split_whitespace().map(str::to_owned).collect())
        .collect()
}

/// Copies `from` into `to`, recursively.
fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let target = to.join(entry.file_name());
        if entry.file_type().unwrap().is_dir() {
            copy_tree(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), &target).unwrap();
        }
    }
}

/// Every file below `dir` with its content.
fn snapshot(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut files = BTreeMap::new();
    let mut pending = vec![dir.to_path_buf()];
    while let Some(d) = pending.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                pending.push(path);
            } else {
                files.insert(path.clone(), std::fs::read(&path).unwrap());
            }
        }
    }
    files
}

#[test]
fn the_opening_block_parses_into_haarshift_commands() {
    let readme = "# x\n\n```sh\ncargo run --release -p haarshift-cli -- experiment a --b 1\n\
                  cargo test --workspace --release\n```\n\n```sh\n\
                  cargo run --release -p haarshift-cli -- later\n```\n";
    assert_eq!(
        opening_commands(readme),
        vec![vec!["experiment", "a", "--b", "1"]]
    );
}

#[test]
fn the_readme_opening_commands_succeed_on_a_fresh_copy_and_when_run_again() {
    let readme = std::fs::read_to_string(repository().join("README.md")).unwrap();
    let commands = opening_commands(&readme);
    assert!(
        !commands.is_empty(),
        "the README's first code block has no `{CARGO_RUN}` line"
    );
    let work = tempfile::tempdir().unwrap();
    let clone = work.path().join("haarshift");
    for dir in ["testdata", "results"] {
        copy_tree(&repository().join(dir), &clone.join(dir));
    }
    std::fs::copy(repository().join("README.md"), clone.join("README.md")).unwrap();
    let committed = snapshot(&clone.join("results"));
    assert!(
        !committed.is_empty(),
        "results/ holds the committed reports"
    );
    // The scratch directory of the experiments goes under the test's own temporary directory.
    let scratch = work.path().join("tmp");
    std::fs::create_dir_all(&scratch).unwrap();
    for args in &commands {
        for attempt in ["first", "second"] {
            let out = Command::new(env!("CARGO_BIN_EXE_haarshift"))
                .args(args)
                .current_dir(&clone)
                .env("TMPDIR", &scratch)
                .output()
                .unwrap();
            let stdout = String::from_utf8_lossy(&out.stdout);
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert!(
                out.status.success(),
                "`haarshift {}` failed on the {attempt} run: {stderr}",
                args.join(" ")
            );
            assert!(
                stdout.lines().any(|l| l.starts_with("|---")),
                "`haarshift {}` printed no table on the {attempt} run:\n{stdout}",
                args.join(" ")
            );
            if args[0] == "experiment" {
                assert!(
                    stdout.contains(&*scratch.to_string_lossy()),
                    "an experiment's reports go to its scratch directory:\n{stdout}"
                );
            }
        }
    }
    assert_eq!(
        snapshot(&clone.join("results")),
        committed,
        "the README's commands changed the committed results/"
    );
}

/// Flags whose README values make a command take minutes, and the value the test runs instead:
/// the same command on a coarser map, fewer frames or sparser occlusion fields.
const SMALLER: &[(&str, &str)] = &[
    ("--resolution", "16"),
    ("--frames", "2"),
    ("--rotation-cache", "8"),
];

/// Flags the test adds to `relight scene` and `relight view SCENE.json` (the occlusion fields'
/// sampling, 29,720 points a shape by default), so that each scene command takes seconds.
const SPARSER_FIELDS: &[&str] = &["--circles", "10", "--circle-points", "20", "--shells", "4"];

/// A line of the README's later `sh` blocks that the test runs.
#[derive(Debug, PartialEq)]
enum Step {
    /// A `haarshift` command: its arguments.
    Haarshift(Vec<String>),
    /// `cmp A B`: two files the commands before it wrote, which must be equal.
    Cmp(String, String),
}

/// Every `haarshift` and `cmp` line in the README's `sh` blocks after the first, in order,
/// without trailing `# comments`.
fn later_steps(readme: &str) -> Vec<Step> {
    readme
        .split("```")
        .skip(1)
        .step_by(2)
        .skip(1)
        .filter_map(|block| block.strip_prefix("sh\n"))
        .flat_map(str::lines)
        .filter_map(|line| {
            let line = line.trim();
            let command = line.split(" #").next().unwrap_or(line);
            let (program, rest) = command.split_once(' ')?;
            let words: Vec<String> = rest.split_whitespace().map(str::to_owned).collect();
            match (program, words.as_slice()) {
                ("haarshift", _) => Some(Step::Haarshift(words)),
                ("cmp", [a, b]) => Some(Step::Cmp(a.clone(), b.clone())),
                // A comparison the test would otherwise skip without a word.
                ("cmp", _) => panic!("`{command}`: the test compares two files, no options"),
                _ => None,
            }
        })
        .collect()
}

/// `args` as the test runs them: the values of [`SMALLER`] in place of the README's, and
/// [`SPARSER_FIELDS`] for `relight scene`.
fn smaller(args: &[String]) -> Vec<String> {
    let mut out: Vec<String> = args.to_vec();
    for i in 1..out.len() {
        if let Some((_, value)) = SMALLER.iter().find(|(flag, _)| out[i - 1] == *flag) {
            out[i] = (*value).to_owned();
        }
    }
    let builds_fields = match out.as_slice() {
        [relight, scene, ..] if relight == "relight" && scene == "scene" => true,
        [relight, view, file, ..] if relight == "relight" && view == "view" => {
            file.ends_with(".json")
        }
        _ => false,
    };
    if builds_fields {
        out.extend(SPARSER_FIELDS.iter().map(|s| (*s).to_owned()));
    }
    out
}

#[test]
fn later_blocks_parse_into_haarshift_commands_at_smaller_sizes_and_comparisons() {
    let readme = "```sh\ncargo run --release -p haarshift-cli -- first\n```\n\
                  ```text\nhaarshift not-a-command\n```\n\
                  ```sh\nhaarshift rotate a.png -o b.png   # a comment\n\
                  haarshift relight scene s.json --resolution 64 -o s.png\n\
                  cmp s.png b.png   # byte for byte\nbash other.sh\n```\n";
    let words = |w: &[&str]| w.iter().map(|s| (*s).to_owned()).collect::<Vec<_>>();
    let rotate = words(&["rotate", "a.png", "-o", "b.png"]);
    let scene = [
        "relight",
        "scene",
        "s.json",
        "--resolution",
        "64",
        "-o",
        "s.png",
    ];
    assert_eq!(
        later_steps(readme),
        vec![
            Step::Haarshift(rotate.clone()),
            Step::Haarshift(words(&scene)),
            Step::Cmp("s.png".into(), "b.png".into()),
        ]
    );
    let commands = [rotate, words(&scene)];
    assert_eq!(smaller(&commands[0]), commands[0]);
    let mut expected: Vec<&str> = vec!["relight", "scene", "s.json", "--resolution", "16"];
    expected.extend(["-o", "s.png"]);
    expected.extend(SPARSER_FIELDS);
    assert_eq!(smaller(&commands[1]), expected);
}

#[test]
fn every_later_readme_command_runs_from_the_root_of_a_fresh_copy() {
    let readme = std::fs::read_to_string(repository().join("README.md")).unwrap();
    let steps = later_steps(&readme);
    let compared = steps.iter().filter(|s| matches!(s, Step::Cmp(..))).count();
    assert!(
        steps.len() - compared >= 20 && compared >= 1,
        "the README's sh blocks hold {} haarshift commands and {compared} comparisons",
        steps.len() - compared
    );
    let work = tempfile::tempdir().unwrap();
    let clone = work.path().join("haarshift");
    for dir in ["testdata", "results"] {
        copy_tree(&repository().join(dir), &clone.join(dir));
    }
    for step in &steps {
        let args = match step {
            Step::Haarshift(args) => smaller(args),
            Step::Cmp(a, b) => {
                let read = |name: &str| std::fs::read(clone.join(name)).unwrap();
                assert!(read(a) == read(b), "`cmp {a} {b}`: the files differ");
                continue;
            }
        };
        if args.starts_with(&["relight".to_owned(), "view".to_owned()]) {
            serves_its_page(&args, &clone);
            continue;
        }
        let out = Command::new(env!("CARGO_BIN_EXE_haarshift"))
            .args(&args)
            .current_dir(&clone)
            .env("TMPDIR", work.path())
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "`haarshift {}` failed: {}",
            args.join(" "),
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

/// `haarshift ARGS` (a `relight view`) on a free port in `dir`: it prints its address and serves
/// the page there; it is stopped when dropped.
fn serves_its_page(args: &[String], dir: &Path) {
    let args: Vec<&str> = args[2..].iter().map(String::as_str).collect();
    let view = crate::viewer::ViewProcess::start_in(Some(dir), &args);
    let host = crate::viewer::authority(&view.url);
    let request = format!("GET / HTTP/1.1\r\nHost: {host}\r\n\r\n");
    let page = crate::viewer::http(&view.url, request.as_bytes());
    assert!(
        page.starts_with("HTTP/1.1 200"),
        "`relight view {}`: {page}",
        args.join(" ")
    );
}

/// The example programs the README's `sh` blocks run: `(name, arguments)`.
fn example_runs(readme: &str) -> Vec<(String, Vec<String>)> {
    readme
        .lines()
        .filter_map(|line| {
            let line = line.trim().strip_prefix("cargo run --release -p ")?;
            let (_, rest) = line.split_once(" --example ")?;
            let (name, args) = rest.split_once(" -- ").unwrap_or((rest, ""));
            Some((
                name.to_owned(),
                args.split_whitespace().map(str::to_owned).collect(),
            ))
        })
        .collect()
}

#[test]
fn every_readme_example_program_runs_as_written() {
    let readme = std::fs::read_to_string(repository().join("README.md")).unwrap();
    let runs = example_runs(&readme);
    assert!(
        runs.len() >= 2,
        "the README runs {} example programs",
        runs.len()
    );
    let work = tempfile::tempdir().unwrap();
    for (name, args) in runs {
        let args: Vec<String> = args
            .iter()
            .map(|a| match a.strip_prefix("/tmp/") {
                Some(rest) => work.path().join(rest).display().to_string(),
                None => a.clone(),
            })
            .collect();
        crate::common::run_example(&name, &args);
    }
}
