//! Reading a ROM file of any [`RomFormat`] back into its words, so that tests check every
//! format against the same codes.

use super::RomFormat;

/// The words of a ROM file in `format`, by address, as written by [`write`](super::write).
///
/// # Errors
/// A message naming the line that does not parse, or a missing or out-of-order address.
pub fn parse(text: &str, format: RomFormat) -> Result<Vec<u128>, String> {
    let comment = format.comment();
    let lines = text.lines().enumerate().filter_map(|(n, line)| {
        // In a .coe, `;` also ends a statement, so only a whole line can be a comment.
        let code = if format == RomFormat::Coe {
            if line.trim_start().starts_with(comment) {
                ""
            } else {
                line.trim()
            }
        } else {
            line.split(comment).next().unwrap_or("").trim()
        };
        (!code.is_empty()).then_some((n + 1, code))
    });
    let number = |n: usize, digits: &str| {
        u128::from_str_radix(digits.trim(), 16)
            .map_err(|e| format!("line {n}: `{digits}` is not a hex word: {e}"))
    };
    let mut words = Vec::new();
    match format {
        RomFormat::Mem => {
            for (n, code) in lines {
                words.push(number(n, code)?);
            }
        }
        RomFormat::Coe => {
            let mut in_vector = false;
            for (n, code) in lines {
                if code == "memory_initialization_radix=16;" {
                    continue;
                }
                if let Some(rest) = code.strip_prefix("memory_initialization_vector=") {
                    in_vector = true;
                    if rest.is_empty() {
                        continue;
                    }
                }
                if !in_vector {
                    return Err(format!("line {n}: `{code}` before the vector"));
                }
                let value = code.trim_end_matches([',', ';']);
                words.push(number(n, value)?);
            }
        }
        RomFormat::Mif => {
            let mut depth = None;
            for (n, code) in lines {
                if let Some(d) = code.strip_prefix("DEPTH=") {
                    depth = d.trim_end_matches(';').parse::<usize>().ok();
                } else if let Some((address, data)) = code.split_once(':') {
                    let address: usize = address
                        .trim()
                        .parse()
                        .map_err(|e| format!("line {n}: bad address: {e}"))?;
                    if address != words.len() {
                        return Err(format!("line {n}: address {address} out of order"));
                    }
                    words.push(number(n, data.trim().trim_end_matches(';'))?);
                }
            }
            if depth != Some(words.len()) {
                return Err(format!("DEPTH {depth:?} but {} addresses", words.len()));
            }
        }
        RomFormat::VerilogInclude | RomFormat::SystemVerilogPackage => {
            for (n, code) in lines {
                if let Some((_, digits)) = code.split_once("'h") {
                    words.push(number(n, digits.trim_end_matches(','))?);
                }
            }
            words.reverse();
        }
        RomFormat::VhdlPackage => {
            for (n, code) in lines {
                if let Some((address, literal)) = code.split_once("=>") {
                    let address: usize = address
                        .trim()
                        .parse()
                        .map_err(|e| format!("line {n}: bad address: {e}"))?;
                    if address != words.len() {
                        return Err(format!("line {n}: address {address} out of order"));
                    }
                    let digits = literal
                        .split_once("x\"")
                        .and_then(|(_, rest)| rest.split_once('"'))
                        .map(|(digits, _)| digits)
                        .ok_or_else(|| format!("line {n}: no x\"...\" literal"))?;
                    words.push(number(n, digits)?);
                }
            }
        }
    }
    Ok(words)
}
