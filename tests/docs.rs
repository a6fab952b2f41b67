//! The docs hold to the program: the command-line and default-config reference pages are
//! generated from it (a stale page fails here; `GYROFX_UPDATE_DOCS=1` rewrites them), every
//! help line fits 100 columns, every guide page is in the summary and every relative link in
//! the README and the guide resolves, the README stays short, and the licence files exist.
//! The figures the guide quotes are held to the code in [`figures`]; the API references and
//! the manifest schema are generated in [`api_reference`] and [`manifest_schema`].

mod api_reference;
mod figures;
mod manifest_schema;

use std::path::{Path, PathBuf};

use crate::common::*;

fn repository() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn guide() -> PathBuf {
    repository().join("docs/guide/src")
}

/// The subcommands as `gyrofx --help` lists them (without `help`).
fn commands() -> Vec<String> {
    let help = ok(&["--help"]);
    help.lines()
        .skip_while(|line| !line.starts_with("Commands:"))
        .skip(1)
        .take_while(|line| line.starts_with("  "))
        // A summary wrapped onto the next line is indented further than the names.
        .filter(|line| !line.starts_with("   "))
        .filter_map(|line| line.split_whitespace().next())
        .filter(|name| *name != "help")
        .map(str::to_string)
        .collect()
}

/// `GYROFX_UPDATE_DOCS=1` writes `text` to `path`; otherwise `path` must hold exactly `text`.
fn generated_page(path: &Path, text: &str) {
    if std::env::var_os("GYROFX_UPDATE_DOCS").is_some() {
        std::fs::write(path, text).unwrap();
        return;
    }
    let on_disk = std::fs::read_to_string(path).unwrap_or_default();
    assert!(
        on_disk == text,
        "{} is stale: GYROFX_UPDATE_DOCS=1 cargo test --test main docs:: rewrites it",
        path.display()
    );
}

#[test]
fn every_help_line_fits_100_columns() {
    let mut pages = vec![("gyrofx".to_string(), ok(&["--help"]))];
    for command in commands() {
        pages.push((format!("gyrofx {command}"), ok(&[&command, "--help"])));
    }
    assert!(pages.len() > 10);
    for (name, help) in pages {
        for line in help.lines() {
            assert!(
                line.chars().count() <= 100,
                "{name} --help: {} columns: {line}",
                line.chars().count()
            );
        }
    }
}

#[test]
fn the_command_line_reference_is_generated_from_the_help() {
    let mut page = String::from(
        "# Command line\n\n<!-- generated from `gyrofx --help` by tests/docs.rs; \
         GYROFX_UPDATE_DOCS=1 cargo test --test main docs:: rewrites it -->\n\n\
         What each command does in context: [commands in detail](commands.md).\n\n",
    );
    page.push_str(&format!("## gyrofx\n\n```text\n{}```\n", ok(&["--help"])));
    for command in commands() {
        let help = ok(&[&command, "--help"]);
        page.push_str(&format!("\n## gyrofx {command}\n\n```text\n{help}```\n"));
    }
    generated_page(&guide().join("reference/cli.md"), &page);
}

#[test]
fn the_config_reference_is_the_annotated_default_config() {
    let mut page = String::from(
        "# The default config\n\n<!-- generated from `gyrofx init` by tests/docs.rs; \
         GYROFX_UPDATE_DOCS=1 cargo test --test main docs:: rewrites it -->\n\n\
         Every key with its unit and default, as `gyrofx init` prints it (the annotated config \
         embedded in the binary). A config file overrides any of them; `--preset` overlays \
         come first. What the keys mean together: [the config](config.md).\n\n",
    );
    page.push_str(&format!("```toml\n{}```\n", ok(&["init"])));
    for preset in ["gu2019", "xue2015", "mpu6050"] {
        let overlay = ok(&["init", "--preset", preset]);
        page.push_str(&format!("\n## Preset {preset}\n\n```toml\n{overlay}```\n"));
    }
    generated_page(&guide().join("reference/default-config.md"), &page);
}

/// The relative link targets of a Markdown text (not inside code blocks; anchors dropped).
fn relative_links(text: &str) -> Vec<String> {
    let mut links = Vec::new();
    let mut fenced = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced {
            continue;
        }
        let mut rest = line;
        while let Some(start) = rest.find("](") {
            rest = &rest[start + 2..];
            let Some(end) = rest.find(')') else { break };
            let target = &rest[..end];
            rest = &rest[end..];
            if target.contains("://") || target.starts_with('#') || target.starts_with("mailto:") {
                continue;
            }
            let path = target.split('#').next().unwrap_or("");
            if !path.is_empty() {
                links.push(path.to_string());
            }
        }
    }
    links
}

fn markdown_files(folder: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(folder).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            markdown_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "md") {
            out.push(path);
        }
    }
}

#[test]
fn every_guide_page_is_in_the_summary_and_every_link_resolves() {
    let summary = std::fs::read_to_string(guide().join("SUMMARY.md")).unwrap();
    let listed: Vec<String> = relative_links(&summary);
    let mut pages = Vec::new();
    markdown_files(&guide(), &mut pages);
    for page in &pages {
        let relative = page
            .strip_prefix(guide())
            .unwrap()
            .to_string_lossy()
            .into_owned();
        if relative != "SUMMARY.md" {
            assert!(
                listed.contains(&relative),
                "{relative} is not in SUMMARY.md"
            );
        }
    }
    let mut documents = pages.clone();
    documents.push(repository().join("README.md"));
    documents.push(repository().join("CONTRIBUTING.md"));
    let mut checked = 0;
    for document in documents {
        let text = std::fs::read_to_string(&document).unwrap();
        for link in relative_links(&text) {
            let target = document.parent().unwrap().join(&link);
            assert!(
                target.exists(),
                "{}: link {link} leads nowhere",
                document.display()
            );
            checked += 1;
        }
    }
    assert!(checked > 50, "{checked} links");
}

/// A link check that cannot find a broken link proves nothing.
#[test]
fn a_broken_link_is_found() {
    let links = relative_links(
        "see [x](a/b.md#c), [y](https://e.org), `[z](q.md)`\n```\n[w](no.md)\n```\n",
    );
    assert_eq!(links, ["a/b.md", "q.md"]);
}

#[test]
fn the_readme_is_short_and_the_licence_is_stated() {
    let readme = std::fs::read_to_string(repository().join("README.md")).unwrap();
    assert!(
        readme.lines().count() <= 200,
        "README.md: {} lines",
        readme.lines().count()
    );
    assert!(readme.starts_with("# gyrofx\n\n```sh\ncargo run --release -- generate --out build"));
    for file in ["LICENSE-MIT", "LICENSE-APACHE"] {
        let text = std::fs::read_to_string(repository().join(file)).unwrap();
        assert!(text.len() > 1000, "{file}");
    }
    let mut manifests = vec![
        repository().join("Cargo.toml"),
        repository().join("python/Cargo.toml"),
    ];
    for crate_folder in ["model", "job", "codegen", "lab", "capi"] {
        manifests.push(repository().join(crate_folder).join("Cargo.toml"));
    }
    for manifest in manifests {
        let text = std::fs::read_to_string(&manifest).unwrap();
        assert!(
            text.contains("license = \"MIT OR Apache-2.0\"")
                || text.contains("license.workspace = true"),
            "{}",
            manifest.display()
        );
    }
    let pyproject = std::fs::read_to_string(repository().join("python/pyproject.toml")).unwrap();
    assert!(pyproject.contains("license = { text = \"MIT OR Apache-2.0\" }"));
}
