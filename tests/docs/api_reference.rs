//! The Python and C API reference pages, generated from the type stubs
//! (`python/gyrofx/__init__.pyi`, which `mypy.stubtest` holds to the compiled module) and the
//! header (`capi/include/gyrofx.h`, which `capi/tests/header.rs` holds to cbindgen's output):
//! every class, method, attribute and function with its signature and doc, so a page cannot
//! miss a name the package has or keep one it lost.

use std::fmt::Write as _;

use super::{generated_page, guide, repository};

/// The generated-page marker both pages start with.
fn header(title: &str, source: &str) -> String {
    format!(
        "# {title}\n\n<!-- Generated from {source} by tests/docs/api_reference.rs: \
         GYROFX_UPDATE_DOCS=1 cargo test --test main docs:: rewrites it -->\n\n"
    )
}

/// A docstring's or comment's text for Markdown: RST's ``code`` becomes `code`.
fn markdown(doc: &str) -> String {
    doc.replace("``", "`")
}

/// One signature on one line: whitespace collapsed, no trailing comma before `)`.
fn one_line(signature: &str) -> String {
    let collapsed = signature.split_whitespace().collect::<Vec<_>>().join(" ");
    collapsed
        .replace("( ", "(")
        .replace(", )", ")")
        .replace(",)", ")")
}

/// A stub's `def` or `class` statement with its docstring, and what decorates it.
#[derive(Debug, Default)]
struct Item {
    signature: String,
    doc: String,
    decorators: Vec<String>,
}

/// A class of the stubs: its doc, attributes (`name: type`) and members.
#[derive(Debug, Default)]
struct Class {
    name: String,
    item: Item,
    attributes: Vec<String>,
    members: Vec<Item>,
}

/// What the stubs declare, in source order.
#[derive(Debug, Default)]
struct Stubs {
    module_doc: String,
    variables: Vec<String>,
    functions: Vec<Item>,
    classes: Vec<Class>,
}

/// The indentation of a line, in spaces.
fn indent(line: &str) -> usize {
    line.len() - line.trim_start().len()
}

/// Reads a docstring starting at `lines[*at]` (which opens with `"""`), moving past it.
fn docstring(lines: &[&str], at: &mut usize) -> String {
    let first = lines[*at].trim().trim_start_matches("\"\"\"");
    if let Some(text) = first.strip_suffix("\"\"\"") {
        *at += 1;
        return text.trim().to_string();
    }
    let mut text = vec![first.trim().to_string()];
    *at += 1;
    while *at < lines.len() {
        let line = lines[*at].trim();
        *at += 1;
        if let Some(last) = line.strip_suffix("\"\"\"") {
            text.push(last.trim().to_string());
            break;
        }
        text.push(line.to_string());
    }
    text.join("\n").trim().to_string()
}

/// Reads a `def` or `class` statement from `lines[*at]` to the `:` that ends it, and the
/// docstring that follows, if any.
fn statement(lines: &[&str], at: &mut usize, decorators: Vec<String>) -> Item {
    let own = indent(lines[*at]);
    let mut signature = String::new();
    let mut depth = 0i32;
    loop {
        let line = lines[*at];
        *at += 1;
        depth += line.matches(['(', '[']).count() as i32;
        depth -= line.matches([')', ']']).count() as i32;
        signature.push_str(line.trim());
        signature.push(' ');
        let end = line.trim_end();
        if depth == 0 && (end.ends_with(':') || end.ends_with(": ...")) {
            break;
        }
    }
    let signature = signature.trim();
    let signature = signature
        .strip_suffix(": ...")
        .or_else(|| signature.strip_suffix(':'))
        .unwrap_or(signature);
    let mut doc = String::new();
    while *at < lines.len() && lines[*at].trim().is_empty() {
        *at += 1;
    }
    if *at < lines.len() && indent(lines[*at]) > own && lines[*at].trim().starts_with("\"\"\"") {
        doc = docstring(lines, at);
    }
    Item {
        signature: one_line(signature),
        doc,
        decorators,
    }
}

/// Parses the stubs (the subset of Python they are written in).
fn parse_stubs(text: &str) -> Stubs {
    let lines: Vec<&str> = text.lines().collect();
    let mut stubs = Stubs::default();
    let mut at = 0;
    if lines.first().is_some_and(|l| l.starts_with("\"\"\"")) {
        stubs.module_doc = docstring(&lines, &mut at);
    }
    let mut decorators = Vec::new();
    let mut class: Option<Class> = None;
    while at < lines.len() {
        let line = lines[at];
        let trimmed = line.trim();
        if trimmed.is_empty() || trimmed.starts_with('#') {
            at += 1;
            continue;
        }
        let top = indent(line) == 0;
        if top {
            if let Some(done) = class.take() {
                stubs.classes.push(done);
            }
        }
        if let Some(decorator) = trimmed.strip_prefix('@') {
            decorators.push(decorator.to_string());
            at += 1;
        } else if trimmed.starts_with("class ") {
            let item = statement(&lines, &mut at, std::mem::take(&mut decorators));
            let name = item.signature["class ".len()..]
                .split(['(', ':'])
                .next()
                .unwrap_or_default()
                .trim()
                .to_string();
            class = Some(Class {
                name,
                item,
                ..Class::default()
            });
        } else if trimmed.starts_with("def ") {
            let item = statement(&lines, &mut at, std::mem::take(&mut decorators));
            match (&mut class, top) {
                (Some(class), false) => class.members.push(item),
                _ => stubs.functions.push(item),
            }
        } else if trimmed.starts_with("__all__") {
            while at < lines.len() && !lines[at].contains(']') {
                at += 1;
            }
            at += 1;
        } else if let (Some(class), false) = (&mut class, top) {
            class.attributes.push(trimmed.to_string());
            at += 1;
        } else {
            if top && trimmed.contains(": ") && !trimmed.contains(" = ") {
                stubs.variables.push(trimmed.to_string());
            }
            at += 1;
        }
    }
    if let Some(done) = class.take() {
        stubs.classes.push(done);
    }
    stubs
}

/// The Python reference page.
fn python_page(stubs: &Stubs) -> String {
    let mut page = header("Python API reference", "python/gyrofx/__init__.pyi");
    let _ = writeln!(page, "{}\n", markdown(&stubs.module_doc));
    let _ = writeln!(
        page,
        "How to use it, with examples: [Python, cocotb and C](python-c.md). Module variables: {}.\n",
        stubs
            .variables
            .iter()
            .map(|v| format!("`{v}`"))
            .collect::<Vec<_>>()
            .join(", ")
    );
    let _ = writeln!(page, "## Functions\n");
    for function in &stubs.functions {
        let _ = writeln!(page, "```python\n{}\n```\n", function.signature);
        if !function.doc.is_empty() {
            let _ = writeln!(page, "{}\n", markdown(&function.doc));
        }
    }
    let (private, public): (Vec<&Class>, Vec<&Class>) =
        stubs.classes.iter().partition(|c| c.name.starts_with('_'));
    for class in public {
        let _ = writeln!(page, "\n## {}\n", class.name);
        let _ = writeln!(page, "```python\n{}\n```\n", class.item.signature);
        if !class.item.doc.is_empty() {
            let _ = writeln!(page, "{}\n", markdown(&class.item.doc));
        }
        for attribute in &class.attributes {
            let _ = writeln!(page, "- attribute `{attribute}`");
        }
        for member in &class.members {
            if member.decorators.iter().any(|d| d == "property") {
                // `def name(self) -> type` reads as an attribute: `name -> type`.
                let name = member
                    .signature
                    .trim_start_matches("def ")
                    .replace("(self)", "");
                let doc = markdown(&member.doc).replace('\n', " ");
                let _ = writeln!(
                    page,
                    "- property `{name}`{}",
                    if doc.is_empty() {
                        String::new()
                    } else {
                        format!(": {doc}")
                    }
                );
                continue;
            }
            let decorators: String = member
                .decorators
                .iter()
                .map(|d| format!("@{d}\n"))
                .collect();
            let _ = writeln!(page, "\n```python\n{decorators}{}\n```\n", member.signature);
            if !member.doc.is_empty() {
                let _ = writeln!(page, "{}\n", markdown(&member.doc));
            }
        }
    }
    let _ = writeln!(
        page,
        "\n## Returned dicts\n\nWhat `step` returns, typed (`process`: the same keys, numpy arrays).\n"
    );
    let _ = writeln!(page, "| type | keys |\n|---|---|");
    for class in private {
        let keys: Vec<String> = class.attributes.iter().map(|a| format!("`{a}`")).collect();
        let _ = writeln!(page, "| `{}` | {} |", class.name, keys.join(", "));
    }
    tidy(page)
}

/// One blank line between blocks, never two.
fn tidy(mut page: String) -> String {
    while page.contains("\n\n\n") {
        page = page.replace("\n\n\n", "\n\n");
    }
    page
}

/// One declaration of the header with the comment above it.
struct Declaration {
    doc: String,
    code: String,
}

/// The header's types and functions, in order.
fn parse_header(text: &str) -> (Vec<Declaration>, Vec<Declaration>) {
    let (mut types, mut functions) = (Vec::new(), Vec::new());
    let mut doc: Vec<String> = Vec::new();
    let mut lines = text.lines();
    let mut in_block_comment = false;
    while let Some(line) = lines.next() {
        let trimmed = line.trim();
        // The banner `/* … */` is the file's, not a declaration's.
        if in_block_comment || trimmed.starts_with("/*") {
            in_block_comment = !trimmed.ends_with("*/");
            continue;
        }
        if let Some(comment) = trimmed.strip_prefix("//") {
            doc.push(comment.strip_prefix(' ').unwrap_or(comment).to_string());
            continue;
        }
        if trimmed.starts_with("typedef struct") {
            types.push(Declaration {
                doc: doc.join("\n"),
                code: trimmed.to_string(),
            });
        } else if trimmed.contains("gyrofx_") && trimmed.contains('(') {
            let mut code = trimmed.to_string();
            while !code.ends_with(';') {
                let Some(next) = lines.next() else { break };
                code.push(' ');
                code.push_str(next.trim());
            }
            functions.push(Declaration {
                doc: doc.join("\n"),
                code: one_line(&code),
            });
        }
        doc.clear();
    }
    (types, functions)
}

/// A header comment for Markdown: its `# Safety` heading becomes a bold lead-in.
fn c_doc(doc: &str) -> String {
    markdown(&doc.replace("# Safety\n", "**Safety.** "))
}

/// The C reference page.
fn c_page(header_text: &str) -> String {
    let (types, functions) = parse_header(header_text);
    let mut page = header("C API reference", "capi/include/gyrofx.h");
    let _ = writeln!(
        page,
        "`#include <gyrofx.h>`; link `libgyrofx_capi.a` (with `-lpthread -ldl -lm`) or \
         `libgyrofx_capi.so`, or ask `pkg-config --cflags --libs gyrofx_capi`. How to use it, \
         with DPI-C: [Python, cocotb and C](python-c.md).\n"
    );
    let _ = writeln!(page, "## Types\n\n| type | what it is |\n|---|---|");
    for t in &types {
        let name = t.code.split_whitespace().last().unwrap_or_default();
        let _ = writeln!(
            page,
            "| `{}` | {} |",
            name.trim_end_matches(';'),
            markdown(&t.doc).replace('\n', " ")
        );
    }
    let _ = writeln!(page, "\n## Functions\n");
    for f in &functions {
        let _ = writeln!(page, "```c\n{}\n```\n\n{}\n", f.code, c_doc(&f.doc));
    }
    tidy(page)
}

#[test]
fn the_python_and_c_references_are_generated_from_the_stubs_and_the_header() {
    let root = repository();
    let stubs = std::fs::read_to_string(root.join("python/gyrofx/__init__.pyi")).unwrap();
    generated_page(
        &guide().join("reference/python-api.md"),
        &python_page(&parse_stubs(&stubs)),
    );
    let header_text = std::fs::read_to_string(root.join("capi/include/gyrofx.h")).unwrap();
    generated_page(&guide().join("reference/c-api.md"), &c_page(&header_text));
}

/// The parsers see every name: a stub class and method, a multi-line signature, a header
/// function; a name dropped from the source drops from the page.
#[test]
fn the_references_list_every_name() {
    let stubs = parse_stubs(
        "\"\"\"Doc.\"\"\"\n\n__version__: str\n\n@final\nclass Kf:\n    \"\"\"The KF.\"\"\"\n\n    \
         latency_clocks: int\n    def step(\n        self,\n        z: int,\n    ) -> int:\n        \
         \"\"\"One step.\"\"\"\n    def reset(self) -> None: ...\n\ndef to_real(codes: int) -> float: ...\n",
    );
    let page = python_page(&stubs);
    for want in [
        "## Kf",
        "def step(self, z: int) -> int",
        "One step.",
        "def reset(self) -> None",
        "attribute `latency_clocks: int`",
        "def to_real(codes: int) -> float",
        "`__version__: str`",
    ] {
        assert!(page.contains(want), "{want} missing from:\n{page}");
    }
    let page = c_page(
        "/* The banner, naming libgyrofx_capi.a (with\n * -lm). */\n// A plan.\ntypedef struct GyrofxPlan GyrofxPlan;\n// Frees it.\n//\n// # Safety\n// \
         Once.\nvoid gyrofx_plan_free(struct GyrofxPlan *plan,\n    int x);\n",
    );
    for want in [
        "| `GyrofxPlan` | A plan. |",
        "void gyrofx_plan_free(struct GyrofxPlan *plan, int x);",
        "**Safety.** Once.",
    ] {
        assert!(page.contains(want), "{want} missing from:\n{page}");
    }
    for unwanted in ["banner", "\n\n\n"] {
        assert!(!page.contains(unwanted), "{unwanted:?} in:\n{page}");
    }
}
