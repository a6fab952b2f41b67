//! A JUnit XML summary of simulation outcomes, the format CI systems (Jenkins, GitLab, GitHub
//! test reporters) read: one `<testsuite>` per simulator, one `<testcase>` per block, a
//! `<failure>` with the testbench's `FAIL` line as its message and its first mismatches (or the
//! build log when it printed none) as its text.

use std::fmt::Write as _;

use crate::simulate::Outcome;

/// `text` escaped for XML attribute values and character data; characters XML 1.0 forbids
/// (control characters other than tab, newline, carriage return) become `?`.
fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            '\t' | '\n' | '\r' => out.push(c),
            c if (c as u32) < 0x20 => out.push('?'),
            c => out.push(c),
        }
    }
    out
}

/// The JUnit XML document of `outcomes`.
pub fn report(outcomes: &[Outcome]) -> String {
    let tests: usize = outcomes.iter().map(|o| o.blocks.len()).sum();
    let failures: usize = outcomes
        .iter()
        .map(|o| o.blocks.iter().filter(|b| !b.passed).count())
        .sum();
    let mut out = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let _ = writeln!(
        out,
        "<testsuites name=\"gyrofx verify\" tests=\"{tests}\" failures=\"{failures}\">"
    );
    for outcome in outcomes {
        let name = outcome.simulator.name();
        let seconds: f64 = outcome.blocks.iter().map(|b| b.seconds).sum();
        let _ = writeln!(
            out,
            "  <testsuite name=\"{name}\" tests=\"{}\" failures=\"{}\" time=\"{seconds:.3}\">",
            outcome.blocks.len(),
            outcome.blocks.iter().filter(|b| !b.passed).count(),
        );
        for block in &outcome.blocks {
            let _ = write!(
                out,
                "    <testcase classname=\"gyrofx.{name}\" name=\"{}\" time=\"{:.3}\"",
                escape(&block.block),
                block.seconds
            );
            if block.passed {
                out.push_str("/>\n");
                continue;
            }
            let message = block
                .report
                .iter()
                .find(|l| l.starts_with("FAIL"))
                .cloned()
                .unwrap_or_else(|| "FAIL: the testbench did not run to its verdict".into());
            let details = if block.report.is_empty() {
                block.log.clone()
            } else {
                block.report.join("\n")
            };
            let _ = writeln!(
                out,
                ">\n      <failure message=\"{}\">{}</failure>\n    </testcase>",
                escape(&message),
                escape(&details)
            );
        }
        out.push_str("  </testsuite>\n");
    }
    out.push_str("</testsuites>\n");
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simulate::{BlockOutcome, Simulator};

    fn block(name: &str, passed: bool, report: &[&str], log: &str) -> BlockOutcome {
        BlockOutcome {
            block: name.into(),
            passed,
            report: report.iter().map(|s| s.to_string()).collect(),
            log: log.into(),
            seconds: 1.5,
        }
    }

    #[test]
    fn counts_failures_and_escapes_the_failure_text() {
        let outcomes = [Outcome {
            simulator: Simulator::Ghdl,
            blocks: vec![
                block("kf", true, &["PASS n=10"], ""),
                block(
                    "top",
                    false,
                    &[
                        "MISMATCH sample 3 signal a<b expected 1 (1) actual 0 (0)",
                        "FAIL mismatches=1 n=10 first=3",
                    ],
                    "",
                ),
                block("sequencer", false, &[], "error: \"x\" & y\u{1}"),
            ],
        }];
        let xml = report(&outcomes);
        assert!(xml.contains("<testsuites name=\"gyrofx verify\" tests=\"3\" failures=\"2\">"));
        assert!(xml.contains("<testsuite name=\"ghdl\" tests=\"3\" failures=\"2\" time=\"4.500\">"));
        assert!(xml.contains("<testcase classname=\"gyrofx.ghdl\" name=\"kf\" time=\"1.500\"/>"));
        assert!(xml.contains(
            "<failure message=\"FAIL mismatches=1 n=10 first=3\">MISMATCH sample 3 signal a&lt;b"
        ));
        assert!(xml.contains(
            "<failure message=\"FAIL: the testbench did not run to its verdict\">error: &quot;x&quot; &amp; y?</failure>"
        ));
        // Every element opened is closed.
        for tag in ["testsuites", "testsuite", "failure"] {
            assert_eq!(
                xml.matches(&format!("<{tag} ")).count(),
                xml.matches(&format!("</{tag}>")).count(),
                "{tag}"
            );
        }
    }
}
