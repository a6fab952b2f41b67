//! The code's shape: crates depend only downward (model ← job ← codegen ← lab ← the CLI; the
//! Python and C bindings on model and job alone), only the lab runs external programs, and
//! inside a crate no two top-level modules import each other, directly or round a circle.
//!
//! A module's imports are read from its source text: every `crate::<module>` path and every
//! `super::` path that climbs out of its top-level module, in code (comments and the
//! `#[cfg(test)]` part of a file are not imports of the library).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn repository() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Every `.rs` file below `dir`, sorted.
fn sources(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                files.push(path);
            }
        }
    }
    files.sort();
    files
}

/// The module path of a source file relative to the crate's `src/`: `a/b.rs` and `a/b/mod.rs`
/// are `[a, b]`; `lib.rs` and `main.rs` are the root, `[]`.
fn module_path(relative: &Path) -> Vec<String> {
    let mut parts: Vec<String> = relative
        .iter()
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    let file = parts.pop().unwrap();
    let stem = file.trim_end_matches(".rs");
    if !matches!(stem, "mod" | "lib" | "main") {
        parts.push(stem.to_string());
    }
    parts
}

/// The identifiers a path continues with after `at`: one, or each item of a `{…}` group
/// (its first segment).
fn following(text: &str, at: usize) -> Vec<String> {
    let rest = &text[at..];
    let identifier = |s: &str| -> String {
        s.trim_start()
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect()
    };
    if let Some(group) = rest.strip_prefix('{') {
        let mut depth = 0;
        let end = group
            .char_indices()
            .find(|&(_, c)| {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => return true,
                    '}' => depth -= 1,
                    _ => {}
                }
                false
            })
            .map_or(group.len(), |(i, _)| i);
        let mut items = Vec::new();
        let mut depth = 0;
        let mut start = 0;
        for (i, c) in group[..end].char_indices() {
            match c {
                '{' => depth += 1,
                '}' => depth -= 1,
                ',' if depth == 0 => {
                    items.push(identifier(&group[start..i]));
                    start = i + 1;
                }
                _ => {}
            }
        }
        items.push(identifier(&group[start..end]));
        items.retain(|i| !i.is_empty() && i != "self");
        items
    } else {
        vec![identifier(rest)]
    }
}

/// The code of a source file: without its `#[cfg(test)]` part and without comment lines.
fn code(text: &str) -> String {
    let library = text.split("#[cfg(test)]").next().unwrap();
    library
        .lines()
        .filter(|line| !line.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The top-level modules of the crate at `src` and, for each, the other top-level modules its
/// files import.
fn imports(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    imports_below(src, "")
}

/// [`imports`] of the modules below `crate::<inside>` (`inside` empty: the crate's), with
/// `src` their folder: the CLI's commands are all below `crate::commands`.
fn imports_below(src: &Path, inside: &str) -> BTreeMap<String, BTreeSet<String>> {
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for file in sources(src) {
        let relative = file.strip_prefix(src).unwrap();
        let path = module_path(relative);
        let Some(top) = path.first().cloned() else {
            continue;
        };
        if relative.file_name().is_some_and(|n| n == "tests.rs") {
            continue;
        }
        let mut text = code(&std::fs::read_to_string(&file).unwrap());
        if !inside.is_empty() {
            text = text.replace(&format!("crate::{inside}::"), "crate::");
        }
        let edges = graph.entry(top.clone()).or_default();
        for (at, _) in text.match_indices("crate::") {
            let before = text[..at].chars().next_back();
            if before.is_some_and(|c| c.is_ascii_alphanumeric() || c == '_') {
                continue; // `gyrofx_crate::` or the like
            }
            for module in following(&text, at + "crate::".len()) {
                edges.insert(module);
            }
        }
        for (at, _) in text.match_indices("super::") {
            if text[..at].ends_with("super::") {
                continue; // counted from the first `super::` of the chain
            }
            let mut climb = 1;
            let mut next = at + "super::".len();
            while text[next..].starts_with("super::") {
                climb += 1;
                next += "super::".len();
            }
            // A mod.rs file's module is its folder; `super` from it is the folder's parent.
            let depth = path.len();
            if climb < depth {
                continue; // stays inside the top-level module
            }
            if climb == depth {
                for module in following(&text, next) {
                    edges.insert(module);
                }
            }
        }
        edges.remove(&top);
    }
    let modules: BTreeSet<String> = graph.keys().cloned().collect();
    for edges in graph.values_mut() {
        edges.retain(|m| modules.contains(m));
    }
    graph
}

/// The circles of `graph`: each strongly connected set of two or more modules.
fn circles(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    let reaches = |from: &str| -> BTreeSet<String> {
        let mut seen = BTreeSet::new();
        let mut stack = vec![from.to_string()];
        while let Some(m) = stack.pop() {
            for next in &graph[&m] {
                if seen.insert(next.clone()) {
                    stack.push(next.clone());
                }
            }
        }
        seen
    };
    let reach: BTreeMap<&String, BTreeSet<String>> =
        graph.keys().map(|m| (m, reaches(m))).collect();
    let mut found: Vec<Vec<String>> = Vec::new();
    for m in graph.keys() {
        if !reach[m].contains(m) || found.iter().any(|c| c.contains(m)) {
            continue;
        }
        let circle: Vec<String> = graph
            .keys()
            .filter(|n| reach[m].contains(*n) && reach[*n].contains(m))
            .cloned()
            .collect();
        found.push(circle);
    }
    found
}

/// No crate has a circle between its modules: the model, the job, codegen, the lab and the
/// CLI.
#[test]
fn no_crate_has_an_import_circle_between_its_modules() {
    for (krate, src) in [
        ("model", repository().join("model/src")),
        ("job", repository().join("job/src")),
        ("the CLI", repository().join("src/commands")),
        ("codegen", repository().join("codegen/src")),
        ("lab", repository().join("lab/src")),
    ] {
        let inside = if krate == "the CLI" { "commands" } else { "" };
        let graph = imports_below(&src, inside);
        assert!(graph.len() > 2, "{krate}: {graph:?}");
        let found = circles(&graph);
        assert!(found.is_empty(), "{krate} has import circles: {found:?}");
    }
}

/// The check finds a circle where there is one: two modules that import each other, and
/// three round a ring, through `crate::`, a `{…}` group and `super::`.
#[test]
fn the_circle_check_finds_a_planted_circle() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path();
    std::fs::create_dir_all(src.join("c")).unwrap();
    std::fs::write(src.join("lib.rs"), "pub mod a;\npub mod b;\npub mod c;\n").unwrap();
    std::fs::write(src.join("a.rs"), "use crate::{b::Thing, c};\n").unwrap();
    std::fs::write(src.join("b.rs"), "// crate::a in a comment is no import\n").unwrap();
    std::fs::write(src.join("c/mod.rs"), "mod inner;\n").unwrap();
    std::fs::write(src.join("c/inner.rs"), "use super::super::a::X;\n").unwrap();
    let graph = imports(src);
    assert_eq!(
        circles(&graph),
        vec![vec!["a".to_string(), "c".to_string()]]
    );
    std::fs::write(
        src.join("b.rs"),
        "fn f() { crate::a::g() }\n#[cfg(test)]\nmod tests { use crate::c; }\n",
    )
    .unwrap();
    let graph = imports(src);
    assert_eq!(
        circles(&graph),
        vec![vec!["a".to_string(), "b".to_string(), "c".to_string()]]
    );
}

/// Each crate stands on the layers below it only: the bindings and the job on no codegen and
/// no lab, codegen on no lab.
#[test]
fn the_job_and_the_bindings_do_not_depend_on_codegen_nor_codegen_on_the_lab() {
    for (manifest, above) in [
        (
            "model/Cargo.toml",
            &["gyrofx-job", "gyrofx-codegen", "gyrofx-lab"][..],
        ),
        ("job/Cargo.toml", &["gyrofx-codegen", "gyrofx-lab"]),
        ("capi/Cargo.toml", &["gyrofx-codegen", "gyrofx-lab"]),
        ("python/Cargo.toml", &["gyrofx-codegen", "gyrofx-lab"]),
        ("codegen/Cargo.toml", &["gyrofx-lab"]),
    ] {
        let text = std::fs::read_to_string(repository().join(manifest)).unwrap();
        for crate_name in above {
            assert!(
                !text.contains(crate_name),
                "{manifest} depends on {crate_name}"
            );
        }
    }
    let job = std::fs::read_to_string(repository().join("job/Cargo.toml")).unwrap();
    assert!(job.contains("gyrofx-model"), "the job stands on the model");
    let lab = std::fs::read_to_string(repository().join("lab/Cargo.toml")).unwrap();
    assert!(lab.contains("gyrofx-codegen"), "the lab stands on codegen");
}

/// The lab is the only code that starts a program: the model, the job, codegen and the
/// bindings name no `Command` outside their tests (a simulator or yosys run from codegen would
/// be a lab module in the wrong crate).
#[test]
fn only_the_lab_starts_external_programs() {
    for src in [
        "model/src",
        "job/src",
        "codegen/src",
        "capi/src",
        "python/src",
    ] {
        for file in sources(&repository().join(src)) {
            let code = code(&std::fs::read_to_string(&file).unwrap());
            for needle in ["Command::new", "process::Command", "Command}", "Command,"] {
                assert!(
                    !code.contains(needle),
                    "{} starts a program ({needle}): that belongs in lab/",
                    file.display()
                );
            }
        }
    }
    let lab = sources(&repository().join("lab/src"));
    assert!(lab
        .iter()
        .any(|file| { code(&std::fs::read_to_string(file).unwrap()).contains("Command::new") }));
}
