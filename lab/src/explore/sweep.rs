//! The candidates of a sweep: `--vary KEY=FORMAT..FORMAT` (several flags: their Cartesian
//! product) or `--guard-bits A..B` (the chain's analysed nodes together).
//!
//! Parsing has no side effects and needs no config ([`Vary::parse`], [`GuardBits::parse`]);
//! [`candidates`] then checks the keys against what `gyrofx formats` analyses in the job and
//! lists every candidate's formats. Errors are the text of a usage error: the flag, the value
//! and what is allowed.

use gyrofx_model::fx::Format;

use gyrofx_job::formats::Analysis;

/// The most candidates one run explores.
pub const MAX_CANDIDATES: usize = 200;

/// The config keys `--guard-bits` moves together: the chain's nodes whose format `gyrofx
/// formats` analyses and that a key of their own sets (interval means, bias estimates, the
/// KF's state and output). The mean filter sits beside the chain (neither the chain's output
/// nor `gyrofx_top`'s cost sees it), and the loop's nodes are swept with `--vary`.
pub const GUARD_BIT_KEYS: [&str; 4] = [
    "estimator.mean_format",
    "estimator.bias_format",
    "kf.state_format",
    "kf.output_format",
];

/// One `--vary` flag: a config key and the formats it takes, in the order given.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Vary {
    /// The config key, e.g. `kf.state_format`.
    pub key: String,
    /// Every format from the first endpoint to the second, both included.
    pub formats: Vec<Format>,
}

const VARY_SHAPE: &str =
    "KEY=FORMAT..FORMAT, e.g. kf.state_format=s30.20..s40.30 or estimator.mean_format=s24.14..s28.18";

impl Vary {
    /// Parses `KEY=FORMAT..FORMAT`. The endpoints share their integer bits (the fraction bits
    /// step by one, the width with them: `s30.20..s33.23` is s30.20, s31.21, s32.22, s33.23)
    /// or their fraction bits (the width steps by one: `s30.20..s32.20`); either may be the
    /// larger. Whether the key exists is checked by [`candidates`].
    ///
    /// # Errors
    /// The usage error's text, naming `--vary`, the value and what is allowed.
    pub fn parse(text: &str) -> Result<Vary, String> {
        let refuse = |why: String| format!("--vary {text} is not allowed: {why}");
        let Some((key, range)) = text.split_once('=') else {
            return Err(refuse(format!("no '=': give {VARY_SHAPE}")));
        };
        let key = key.trim();
        if key.is_empty() {
            return Err(refuse(format!("no key before '=': give {VARY_SHAPE}")));
        }
        let Some((first, last)) = range.split_once("..") else {
            return Err(refuse(format!(
                "'{range}' is not a range of formats: give {VARY_SHAPE}"
            )));
        };
        let format = |f: &str| -> Result<Format, String> {
            f.trim().parse::<Format>().map_err(|_| {
                refuse(format!(
                    "'{f}' is not a format: s<width>.<frac> or u<width>.<frac> with a width of 1 to 64 bits, e.g. s30.20"
                ))
            })
        };
        let (a, b) = (format(first)?, format(last)?);
        if a.signed != b.signed {
            return Err(refuse(format!(
                "{a} and {b} differ in sign: both endpoints are signed (s) or both unsigned (u)"
            )));
        }
        let formats = steps(a, b).ok_or_else(|| {
            refuse(format!(
                "{a} and {b} share neither their integer bits ({} and {}) nor their fraction bits ({} and {}): give two formats with the same integer bits (the fraction bits step by 1, e.g. s30.20..s40.30) or the same fraction bits (the width steps by 1, e.g. s30.20..s36.20)",
                a.int_bits(),
                b.int_bits(),
                a.frac,
                b.frac
            ))
        })?;
        Ok(Vary {
            key: key.to_string(),
            formats,
        })
    }
}

/// Every format from `a` to `b` one bit apart: fraction bits (same integer bits) or width (same
/// fraction bits); `None` when they share neither.
fn steps(a: Format, b: Format) -> Option<Vec<Format>> {
    let between = |from: i64, to: i64| -> Vec<i64> {
        if from <= to {
            (from..=to).collect()
        } else {
            (to..=from).rev().collect()
        }
    };
    if a.int_bits() == b.int_bits() {
        let int = i64::from(a.int_bits());
        Some(
            between(i64::from(a.frac), i64::from(b.frac))
                .into_iter()
                .map(|frac| Format {
                    signed: a.signed,
                    width: (int + frac) as u32,
                    frac: frac as i32,
                })
                .collect(),
        )
    } else if a.frac == b.frac {
        Some(
            between(i64::from(a.width), i64::from(b.width))
                .into_iter()
                .map(|width| Format {
                    signed: a.signed,
                    width: width as u32,
                    frac: a.frac,
                })
                .collect(),
        )
    } else {
        None
    }
}

/// `--guard-bits A..B`: every key of [`GUARD_BIT_KEYS`] at its configured fraction bits + g
/// (its integer bits kept), for g from A to B (either may be the larger; negative takes bits
/// away).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GuardBits {
    /// The first g.
    pub from: i32,
    /// The last g.
    pub to: i32,
}

impl GuardBits {
    /// Parses `A..B`, two whole numbers.
    ///
    /// # Errors
    /// The usage error's text, naming `--guard-bits`, the value and what is allowed.
    pub fn parse(text: &str) -> Result<GuardBits, String> {
        let refuse = || {
            format!(
                "--guard-bits {text} is not allowed: give A..B, two whole numbers of guard bits added to each node's configured fraction bits, e.g. 0..4 or -2..2"
            )
        };
        let (a, b) = text.split_once("..").ok_or_else(refuse)?;
        let number = |t: &str| t.trim().parse::<i32>().map_err(|_| refuse());
        let (from, to) = (number(a)?, number(b)?);
        if from.unsigned_abs() > 64 || to.unsigned_abs() > 64 {
            return Err(refuse());
        }
        Ok(GuardBits { from, to })
    }

    fn values(self) -> Vec<i32> {
        if self.from <= self.to {
            (self.from..=self.to).collect()
        } else {
            (self.to..=self.from).rev().collect()
        }
    }
}

/// What a run sweeps.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Sweep {
    /// `--vary` flags: the Cartesian product of their formats, the last flag varying fastest.
    Vary(Vec<Vary>),
    /// `--guard-bits`.
    GuardBits(GuardBits),
}

/// One point of the sweep: a format for every swept key.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Candidate {
    /// Its place in the sweep, from 0: the CSV's row order.
    pub index: usize,
    /// `(key, format)` in the order of [`Sweep`]'s keys.
    pub formats: Vec<(&'static str, Format)>,
}

impl Candidate {
    /// Its formats as `key<separator>format`, in the sweep's key order.
    pub fn assignments(&self, separator: &str) -> Vec<String> {
        self.formats
            .iter()
            .map(|(key, format)| format!("{key}{separator}{format}"))
            .collect()
    }
}

/// The keys a sweep may set: every analysed node's key that sets that node's format alone (as
/// `gyrofx formats --write` does), the mean filter's left out (it sits beside the chain).
pub fn explorable_keys(analysis: &Analysis) -> Vec<&'static str> {
    let mut keys: Vec<&'static str> = Vec::new();
    for row in &analysis.rows {
        if let (Some(key), None) = (row.key, row.shared) {
            if !key.starts_with("mean_filter.") && !keys.contains(&key) {
                keys.push(key);
            }
        }
    }
    keys
}

/// Why an analysed key is not explorable (empty for an unknown one).
fn why_not(analysis: &Analysis, key: &str) -> String {
    if key.starts_with("mean_filter.") {
        return " (the mean filter sits beside the chain: neither the chain's output nor gyrofx_top sees it)".into();
    }
    analysis
        .rows
        .iter()
        .find(|r| r.key == Some(key))
        .and_then(|r| r.shared)
        .map(|why| format!(" ({why})"))
        .unwrap_or_default()
}

/// The configured format of `key`: that of the first analysed node it sets.
fn configured(analysis: &Analysis, key: &str) -> Option<Format> {
    analysis
        .rows
        .iter()
        .find(|r| r.key == Some(key))
        .map(|r| r.node.format)
}

/// The swept keys and every candidate of `sweep`, against the nodes `analysis` (of the
/// configured job) covers.
///
/// # Errors
/// The usage error's text: an unknown or repeated key (listing the allowed ones), a format of
/// the wrong sign, guard bits that leave a width outside 1..=64, or more than
/// [`MAX_CANDIDATES`] candidates.
pub fn candidates(
    analysis: &Analysis,
    sweep: &Sweep,
) -> Result<(Vec<&'static str>, Vec<Candidate>), String> {
    let allowed = explorable_keys(analysis);
    let mut axes: Vec<(&'static str, Vec<Format>)> = Vec::new();
    match sweep {
        Sweep::Vary(flags) => {
            if flags.is_empty() {
                return Err(
                    "give at least one --vary KEY=FORMAT..FORMAT, or --guard-bits A..B".into(),
                );
            }
            for vary in flags {
                let Some(key) = allowed.iter().copied().find(|k| *k == vary.key) else {
                    return Err(format!(
                        "--vary {}=…: {} is not a format explore can sweep{}: one of {}",
                        vary.key,
                        vary.key,
                        why_not(analysis, &vary.key),
                        allowed.join(", ")
                    ));
                };
                if axes.iter().any(|(k, _)| *k == key) {
                    return Err(format!(
                        "--vary {key} is given twice: give each key once (several keys sweep their Cartesian product)"
                    ));
                }
                let current = configured(analysis, key).expect("an analysed key");
                if let Some(f) = vary.formats.iter().find(|f| f.signed != current.signed) {
                    return Err(format!(
                        "--vary {key}=…: {f} is not allowed: {key} is {} (configured {current})",
                        if current.signed {
                            "signed (s…)"
                        } else {
                            "unsigned (u…)"
                        }
                    ));
                }
                axes.push((key, vary.formats.clone()));
            }
        }
        Sweep::GuardBits(bits) => {
            for key in GUARD_BIT_KEYS {
                let current = configured(analysis, key).expect("the chain's nodes are analysed");
                let mut formats = Vec::new();
                for g in bits.values() {
                    let width = i64::from(current.width) + i64::from(g);
                    let format = u32::try_from(width)
                        .ok()
                        .and_then(|w| Format::new(current.signed, w, current.frac + g).ok())
                        .ok_or_else(|| {
                            format!(
                                "--guard-bits {}..{} is not allowed: {key} ({current}) with {g} guard bits would be {width} bits wide, and widths are 1 to 64",
                                bits.from, bits.to
                            )
                        })?;
                    formats.push(format);
                }
                axes.push((key, formats));
            }
        }
    }
    let count = match sweep {
        // One candidate per g: every key moves together.
        Sweep::GuardBits(bits) => bits.values().len(),
        Sweep::Vary(_) => axes
            .iter()
            .try_fold(1usize, |n, (_, f)| n.checked_mul(f.len()))
            .unwrap_or(usize::MAX),
    };
    if count > MAX_CANDIDATES {
        let what = match sweep {
            Sweep::Vary(_) => "narrow the --vary ranges or give fewer --vary flags",
            Sweep::GuardBits(_) => "narrow the --guard-bits range",
        };
        return Err(format!(
            "{count} candidates are more than the {MAX_CANDIDATES} one run explores: {what}"
        ));
    }
    let keys: Vec<&'static str> = axes.iter().map(|(k, _)| *k).collect();
    let candidates = (0..count)
        .map(|index| {
            let formats = match sweep {
                Sweep::GuardBits(_) => axes.iter().map(|(k, f)| (*k, f[index])).collect(),
                Sweep::Vary(_) => {
                    // Mixed radix, the last axis fastest.
                    let mut rest = index;
                    let mut picked: Vec<(&'static str, Format)> = axes
                        .iter()
                        .rev()
                        .map(|(k, f)| {
                            let i = rest % f.len();
                            rest /= f.len();
                            (*k, f[i])
                        })
                        .collect();
                    picked.reverse();
                    picked
                }
            };
            Candidate { index, formats }
        })
        .collect();
    Ok((keys, candidates))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn f(text: &str) -> Format {
        text.parse().unwrap()
    }

    #[test]
    fn a_range_steps_the_fraction_bits_or_the_width() {
        let v = Vary::parse("kf.state_format=s30.20..s33.23").unwrap();
        assert_eq!(v.key, "kf.state_format");
        assert_eq!(
            v.formats,
            ["s30.20", "s31.21", "s32.22", "s33.23"].map(f).to_vec()
        );
        let v = Vary::parse("kf.state_format=s32.20..s30.20").unwrap();
        assert_eq!(v.formats, ["s32.20", "s31.20", "s30.20"].map(f).to_vec());
        let v = Vary::parse("kf.state_format=s30.20..s30.20").unwrap();
        assert_eq!(v.formats, vec![f("s30.20")]);
    }

    #[test]
    fn bad_ranges_name_the_flag_the_value_and_what_is_allowed() {
        for (text, says) in [
            ("kf.state_format", "no '='"),
            ("kf.state_format=s30.20", "not a range of formats"),
            ("kf.state_format=s30.20..x", "'x' is not a format"),
            (
                "kf.state_format=s30.20..s32.21",
                "share neither their integer bits (10 and 11)",
            ),
            ("kf.state_format=s30.20..u30.20", "differ in sign"),
            ("=s30.20..s31.21", "no key"),
        ] {
            let message = Vary::parse(text).unwrap_err();
            assert!(
                message.starts_with(&format!("--vary {text} is not allowed: ")),
                "{message}"
            );
            assert!(message.contains(says), "{text}: {message}");
        }
        for text in ["1", "a..b", "1..", "0..100"] {
            let message = GuardBits::parse(text).unwrap_err();
            assert!(
                message.contains(&format!("--guard-bits {text}")),
                "{message}"
            );
        }
        assert_eq!(
            GuardBits::parse("-2..1").unwrap(),
            GuardBits { from: -2, to: 1 }
        );
    }

    fn default_analysis() -> Analysis {
        let job = gyrofx_job::job::Job::new(gyrofx_job::config::Config::embedded()).unwrap();
        gyrofx_job::formats::analyse(&job, 10_000, 10)
    }

    #[test]
    fn several_flags_sweep_their_product_the_last_fastest() {
        let analysis = default_analysis();
        let sweep = Sweep::Vary(vec![
            Vary::parse("kf.state_format=s30.20..s31.21").unwrap(),
            Vary::parse("estimator.mean_format=s26.16..s28.16").unwrap(),
        ]);
        let (keys, list) = candidates(&analysis, &sweep).unwrap();
        assert_eq!(keys, ["kf.state_format", "estimator.mean_format"]);
        let got: Vec<(String, String)> = list
            .iter()
            .map(|c| (c.formats[0].1.to_string(), c.formats[1].1.to_string()))
            .collect();
        let expected: Vec<(String, String)> = [
            ("s30.20", "s26.16"),
            ("s30.20", "s27.16"),
            ("s30.20", "s28.16"),
            ("s31.21", "s26.16"),
            ("s31.21", "s27.16"),
            ("s31.21", "s28.16"),
        ]
        .iter()
        .map(|(a, b)| (a.to_string(), b.to_string()))
        .collect();
        assert_eq!(got, expected);
        assert!(list.iter().enumerate().all(|(i, c)| c.index == i));
    }

    #[test]
    fn guard_bits_move_the_chains_nodes_together_keeping_their_integer_bits() {
        let analysis = default_analysis();
        let (keys, list) =
            candidates(&analysis, &Sweep::GuardBits(GuardBits { from: -1, to: 2 })).unwrap();
        assert_eq!(keys, GUARD_BIT_KEYS);
        assert_eq!(list.len(), 4);
        // The default: means and biases s28.18, state s36.26, output s24.14.
        let third: Vec<String> = list[2].formats.iter().map(|(_, f)| f.to_string()).collect();
        assert_eq!(third, ["s29.19", "s29.19", "s37.27", "s25.15"]);
        let first: Vec<String> = list[0].formats.iter().map(|(_, f)| f.to_string()).collect();
        assert_eq!(first, ["s27.17", "s27.17", "s35.25", "s23.13"]);
    }

    #[test]
    fn keys_outside_the_chain_and_loop_or_shared_are_refused_with_why() {
        let analysis = default_analysis();
        let keys = explorable_keys(&analysis);
        assert!(keys.contains(&"loop.cic_internal_format"));
        for (key, says) in [
            (
                "mean_filter.output_format",
                "the mean filter sits beside the chain",
            ),
            ("kf.input_format", "also the ADC's"),
            ("loop.output_format", "the chain's input format"),
            ("kf.bandwidths_hz", "one of estimator.mean_format"),
        ] {
            assert!(!keys.contains(&key));
            let sweep = Sweep::Vary(vec![Vary {
                key: key.into(),
                formats: vec![f("s24.14")],
            }]);
            let message = candidates(&analysis, &sweep).unwrap_err();
            assert!(message.contains(says), "{key}: {message}");
        }
        let sweep = Sweep::Vary(vec![Vary::parse("kf.state_format=u36.26..u37.27").unwrap()]);
        assert!(candidates(&analysis, &sweep)
            .unwrap_err()
            .contains("kf.state_format is signed"));
    }
}
