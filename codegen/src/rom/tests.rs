//! Tests of the ROM files: every format reads back the packed codes, a corrupted file does not.

use super::*;
use crate::text::Provenance;
use gyrofx_model::examples;

fn provenance() -> Provenance {
    Provenance {
        version: "0.0.0".into(),
        command: "test".into(),
        config_sha256: "0123456789abcdef0123456789abcdef".into(),
    }
}

fn wide_rom() -> Rom {
    // Two 64-bit fields: the widest word, with both signs at the top of their fields.
    let format = Format::signed(64, 62).unwrap();
    Rom {
        name: "wide".into(),
        description: "test".into(),
        fields: vec![
            Field {
                name: "a".into(),
                format,
            },
            Field {
                name: "b".into(),
                format,
            },
        ],
        codes: vec![
            vec![-1, 1],
            vec![i64::MIN.into(), i64::MAX.into()],
            vec![0, -2],
        ],
        notes: vec!["x".into(), "y".into(), "z".into()],
    }
}

#[test]
fn every_format_reads_back_the_packed_codes() {
    let chain = examples::chain_plan(40, 5, 0, 1, gyrofx_model::fx::Rounding::Convergent);
    let roms = [
        Rom::kf(&chain.kf),
        Rom::estimator(&chain.estimator),
        wide_rom(),
    ];
    for rom in &roms {
        // Unpack independently of `Rom::word`: field by field from the bottom.
        let expected: Vec<Vec<i128>> = rom.codes.clone();
        for format in RomFormat::ALL {
            let text = write(rom, format, &provenance());
            assert!(text.contains(format.title()), "{format:?} header");
            assert!(text.contains("gyrofx 0.0.0") && text.contains("0123456789abcdef"));
            let words = parse(&text, format).unwrap_or_else(|e| panic!("{format:?}: {e}"));
            assert_eq!(words.len(), rom.depth(), "{format:?}");
            for (address, word) in words.iter().enumerate() {
                let mut rest = *word;
                let mut fields = Vec::new();
                for field in rom.fields.iter().rev() {
                    fields.push(field.format.from_bits(rest));
                    rest = rest.checked_shr(field.format.width).unwrap_or(0);
                }
                fields.reverse();
                assert_eq!(rest, 0, "{format:?} @{address}: bits above the word");
                assert_eq!(fields, expected[address], "{format:?} @{address}");
            }
        }
    }
}

#[test]
fn a_corrupted_file_does_not_parse_as_the_rom() {
    let rom =
        Rom::kf(&examples::chain_plan(40, 5, 0, 1, gyrofx_model::fx::Rounding::Convergent).kf);
    for format in RomFormat::ALL {
        let text = write(&rom, format, &provenance());
        let good = parse(&text, format).unwrap();
        // Flip the last hex digit of the first data word.
        let first = rom.hex(
            good[if matches!(
                format,
                RomFormat::VerilogInclude | RomFormat::SystemVerilogPackage
            ) {
                good.len() - 1
            } else {
                0
            }],
        );
        let flipped = format!(
            "{}{}",
            &first[..first.len() - 1],
            if first.ends_with('0') { '1' } else { '0' }
        );
        let bad = text.replacen(&first, &flipped, 1);
        assert_ne!(parse(&bad, format).ok(), Some(good), "{format:?}");
    }
}

/// The serial program's ROM packs its fields into exactly the words the instruction set
/// encodes (`Instruction::encode`), whose field positions the engine's RTL decodes.
#[test]
fn the_serial_program_rom_holds_the_encoded_instructions() {
    let plan = examples::chain_plan(40, 5, 3, 1, gyrofx_model::fx::Rounding::Convergent);
    let program = gyrofx_model::serial::compile(&plan).unwrap();
    let text = write(
        &Rom::serial_program(&program),
        RomFormat::Mem,
        &provenance(),
    );
    let words: Vec<u64> = text
        .lines()
        .filter(|l| !l.starts_with("//") && !l.trim().is_empty())
        .map(|l| u64::from_str_radix(l.trim(), 16).unwrap())
        .collect();
    assert_eq!(words, program.rom_words());
    assert!(words
        .iter()
        .any(|w| w >> (program.layout.word_bits() - 4) == 15));
}
