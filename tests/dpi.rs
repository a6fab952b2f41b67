//! The C ABI (`capi/`) end to end: a C program against the header, the package's DPI-C
//! testbenches in Verilator (through `gyrofx verify --sim dpi`), their failure on one flipped
//! expected bit and on a mutated RTL line, and the C++ Verilator harness example.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::common::{capi_library as library, generate_default, run_tool, text};
use gyrofx_job::config::Config;
use gyrofx_job::golden;
use gyrofx_job::job::Job;
use gyrofx_job::pipeline;

/// The repository.
fn repository() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn a_c_program_gets_the_models_results_and_its_errors() {
    let dir = tempfile::tempdir().unwrap();
    let program = dir.path().join("check_api");
    let (built, log) = run_tool(
        "gcc",
        &[
            "-std=c99",
            "-Wall",
            "-Werror",
            "-I",
            repository().join("capi/include").to_str().unwrap(),
            repository()
                .join("capi/examples/check_api.c")
                .to_str()
                .unwrap(),
            library().to_str().unwrap(),
            "-lpthread",
            "-ldl",
            "-lm",
            "-o",
            program.to_str().unwrap(),
        ],
        dir.path(),
    );
    assert!(built, "{log}");
    let (ran, out) = run_tool(program.to_str().unwrap(), &[], dir.path());
    assert!(ran, "{out}");
    assert!(
        out.contains("bad plan NULL: ") && out.contains("kf.bandwidths_hz"),
        "{out}"
    );
    assert!(
        out.contains("refused z: -1 z = 1099511627776 is not a code of"),
        "{out}"
    );
    assert!(
        out.contains("refused bw_sel: -1 bw_sel = 2 does not address"),
        "{out}"
    );
    assert!(out.contains("null step: -1 block is NULL"), "{out}");
    // The error text copied into the caller's buffer outlives the next failure; a short
    // buffer gets a cut, terminated copy and the full length.
    let refused_z = out
        .lines()
        .find_map(|l| l.strip_prefix("refused z: -1 "))
        .expect("the refused z line");
    assert!(
        out.contains(&format!("copied {}: {refused_z}\n", refused_z.len())),
        "{out}"
    );
    let refused_bw_sel = out
        .lines()
        .find_map(|l| l.strip_prefix("refused bw_sel: -1 "))
        .expect("the refused bw_sel line");
    assert!(
        out.contains(&format!(
            "cut {}: {}\n",
            refused_bw_sel.len(),
            &refused_bw_sel[..7]
        )),
        "{out}"
    );
    assert!(out.contains("copy refused: -1 -1"), "{out}");
    // Every block's pipeline, as the package's testbenches and manifest take it.
    let serial = Job::new(Config::from_toml("architecture = \"serial\"\n", "t").unwrap()).unwrap();
    for (line, p) in [
        ("kf", pipeline::KF),
        ("gyro_loop", pipeline::GYRO_LOOP),
        (
            "system",
            pipeline::system(&Job::new(Config::embedded()).unwrap()),
        ),
        ("serial chain", pipeline::top(&serial)),
        ("serial mean_filter", pipeline::mean_filter(&serial)),
        ("estimator", pipeline::ESTIMATOR),
        ("sequencer", pipeline::SEQUENCER),
    ] {
        let want = format!(
            "pipeline {line} {} {}\n",
            p.latency_clocks, p.min_clocks_per_sample
        );
        assert!(out.contains(&want), "{want}{out}");
    }
    assert!(out.contains("pipeline kf 4 3\n"), "{out}");
    assert!(out.contains("null pipeline: -1"), "{out}");
    // The KF's ports, as the golden model lists them (and tests/blocks.rs holds that list to
    // the package's), and the refusal past the last.
    let kf_job =
        Job::new(Config::from_toml("[kf]\nbandwidths_hz = [5.0, 10.0]\n", "t").unwrap()).unwrap();
    let ports = golden::Kf::new(kf_job.kf()).ports();
    let want: Vec<String> = ports
        .iter()
        .map(|p| format!("port kf {} {} {}", p.name, p.direction(), p.format))
        .collect();
    let got: Vec<&str> = out.lines().filter(|l| l.starts_with("port kf ")).collect();
    assert_eq!(got, want);
    assert!(
        out.contains(&format!(
            "no port: -1 port index = {0}: allowed 0 to {1} (the block has {0} ports)",
            ports.len(),
            ports.len() - 1
        )),
        "{out}"
    );
    // The same steps in Rust: the C side must see the same codes.
    let job =
        Job::new(Config::from_toml("[kf]\nbandwidths_hz = [5.0, 10.0]\n", "t").unwrap()).unwrap();
    let mut kf = golden::Kf::new(job.kf());
    let want: Vec<String> = (0..50i64)
        .map(|k| {
            let z = (k * 7919 % 20001) - 10000;
            format!("rate {}", kf.step(z, k / 25).unwrap())
        })
        .collect();
    let got: Vec<&str> = out.lines().filter(|l| l.starts_with("rate ")).collect();
    assert_eq!(got, want);
    // Gyro B's loop and the system: the same codes as the Rust golden blocks.
    assert!(
        out.contains("bad gyro NULL: gyro = 2: allowed 0 (A) or 1 (B)"),
        "{out}"
    );
    assert!(
        out.contains("refused mode: -1 mode = 2: a mode is 1 (normal) or 0 (reverse)"),
        "{out}"
    );
    assert!(
        out.contains(
            "no system for the rate plant, NULL: plant.model = \"rate\" has no system block"
        ),
        "{out}"
    );
    let mut gyro_loop = golden::GyroLoop::new(&job.gyro_loops[1].plan);
    let want: Vec<String> = (0..20i64)
        .map(|k| {
            let [x, y, locked, valid, ..] = gyro_loop
                .step(k * 40009 % 1000003, -k * 7, i64::from(k < 10))
                .unwrap();
            format!("loop {x} {y} {locked} {valid}")
        })
        .collect();
    let got: Vec<&str> = out.lines().filter(|l| l.starts_with("loop ")).collect();
    assert_eq!(got, want);
    let [a, b] = &job.gyro_loops;
    let mut system = golden::System::new([&a.plan, &b.plan], job.system_chain.as_ref().unwrap());
    let want: Vec<String> = (0..20i64)
        .map(|k| {
            let [next_a, next_b] = system.next_modes();
            let o = system
                .step(i64::from(k >= 5), 0, [k * 1000, -k * 1000, k * 77, 3 - k])
                .unwrap();
            format!(
                "system {next_a} {next_b} {} {} {} {} {} {}",
                o[0], o[1], o[2], o[3], o[6], o[7]
            )
        })
        .collect();
    let got: Vec<&str> = out.lines().filter(|l| l.starts_with("system ")).collect();
    assert_eq!(got, want);
    assert!(want.iter().any(|l| !l.ends_with(" 0 0 0 0 1 0")));
}

#[test]
fn the_dpi_testbenches_pass_fail_on_a_flipped_bit_and_on_a_mutated_line() {
    let dir = tempfile::tempdir().unwrap();
    let package = generate_default(dir.path(), "1000");
    let library = library();
    // Every block through verify (Verilator, the model through DPI-C).
    let output = Command::new(env!("CARGO_BIN_EXE_gyrofx"))
        .args(["verify", "--out", package.to_str().unwrap(), "--sim", "dpi"])
        .env("GYROFX_CAPI_LIB", &library)
        .output()
        .unwrap();
    let log = text(&output);
    assert!(output.status.success(), "{log}");
    assert!(log.contains("dpi: passed"), "{log}");
    for block in gyrofx_job::golden::BLOCKS {
        assert!(log.contains(&format!("== {block}")), "{block}: {log}");
    }
    // One flipped expected bit fails it with exactly one mismatch.
    let make = |folder: &Path, target: &str, extra: &[&str]| {
        let mut args = vec![
            "--no-print-directory".to_string(),
            target.to_string(),
            format!("GYROFX_CAPI_LIB={}", library.display()),
        ];
        args.extend(extra.iter().map(|s| s.to_string()));
        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
        run_tool("make", &refs, folder)
    };
    for block in ["kf", "estimator", "gyro_loop", "system"] {
        let (passed, log) = make(
            &package,
            &format!("dpi-{block}"),
            &["DPI_PLUSARGS=+flip=30 +samples=1500"],
        );
        assert!(!passed, "{block}: {log}");
        assert!(log.contains("FAIL mismatches=1 "), "{block}: {log}");
    }
    // A mutated RTL line fails it.
    let rtl = package.join("hdl/gyrofx_kf.v");
    let source = std::fs::read_to_string(&rtl).unwrap();
    assert!(source.contains("x2_reg <= x2_next;"));
    std::fs::write(
        &rtl,
        source.replace("x2_reg <= x2_next;", "x2_reg <= x2_reg;"),
    )
    .unwrap();
    let (passed, log) = make(&package, "dpi-kf", &[]);
    assert!(!passed && log.contains("FAIL mismatches="), "{log}");
    std::fs::write(&rtl, source).unwrap();
    // Without the library the error says what to set.
    let output = Command::new(env!("CARGO_BIN_EXE_gyrofx"))
        .args(["verify", "--out", package.to_str().unwrap(), "--sim", "dpi"])
        .env_remove("GYROFX_CAPI_LIB")
        .output()
        .unwrap();
    assert!(!output.status.success());
    assert!(
        text(&output).contains("GYROFX_CAPI_LIB"),
        "{}",
        text(&output)
    );
}

#[test]
fn the_cpp_verilator_harness_checks_the_kf_against_the_c_api() {
    let dir = tempfile::tempdir().unwrap();
    let package = generate_default(dir.path(), "500");
    let kf = package.join("kf");
    let harness = repository().join("capi/examples/verilator_kf_harness.cpp");
    let ldflags = format!("{} -lpthread -ldl -lm", library().display());
    let include = format!("-I{}", repository().join("capi/include").display());
    let (built, log) = run_tool(
        "verilator",
        &[
            "--cc",
            "--exe",
            "--build",
            "-j",
            "2",
            "-Wno-fatal",
            "-I.",
            "--top-module",
            "cocotb_gyrofx_kf",
            "../hdl/gyrofx_quantize.v",
            "../hdl/gyrofx_spacing_check.v",
            "../hdl/gyrofx_kf.v",
            "../cocotb/cocotb_gyrofx_kf.v",
            harness.to_str().unwrap(),
            "-CFLAGS",
            &include,
            "-LDFLAGS",
            &ldflags,
        ],
        &kf,
    );
    assert!(built, "{log}");
    let (passed, out) = run_tool("./obj_dir/Vcocotb_gyrofx_kf", &["3000"], &kf);
    assert!(passed && out.contains("PASS n=3000"), "{out}");
}

/// The DPI-C type a C parameter or return type of `gyrofx.h` takes (`output` for a pointer to
/// a scalar), or `None` for one DPI-C cannot pass.
fn dpi_type_of(c_type: &str) -> Option<String> {
    let c_type = c_type.trim();
    let scalar = |t: &str| match t {
        "int64_t" => Some("longint"),
        "int32_t" => Some("int"),
        "void" => Some("void"),
        _ => None,
    };
    if c_type == "const char *" || c_type == "const char*" {
        return Some("string".into());
    }
    if c_type.starts_with("struct ") || c_type.starts_with("const struct ") {
        return Some("chandle".into());
    }
    if let Some(pointee) = c_type.strip_suffix('*') {
        return scalar(pointee.trim()).map(|t| format!("output {t}"));
    }
    scalar(c_type).map(str::to_string)
}

/// The package's `gyrofx_dpi_pkg.sv` against `gyrofx.h`: every import names a function of the
/// C library with its arguments in order, each in the DPI-C type of its C type (`chandle` for a
/// handle, `longint` for `int64_t`, `int` for `int32_t`, `string` for `const char *`, `output`
/// for a pointer to a scalar), so the SystemVerilog side cannot drift from the library.
#[test]
fn every_dpi_import_is_the_c_headers_function_in_dpi_types() {
    let package =
        std::fs::read_to_string(repository().join("vectors/dpi/gyrofx_dpi_pkg.sv")).unwrap();
    let header = std::fs::read_to_string(repository().join("capi/include/gyrofx.h")).unwrap();
    let header: String = header
        .lines()
        .filter(|l| !l.trim_start().starts_with("//") && !l.trim_start().starts_with('#'))
        .collect::<Vec<_>>()
        .join(" ");
    let mut checked = 0;
    for statement in package
        .split(';')
        .filter(|s| s.contains("import \"DPI-C\""))
    {
        let signature = statement[statement.find("function ").unwrap() + 9..].trim();
        let (head, arguments) = signature.split_once('(').unwrap();
        let (return_type, name) = head.trim().rsplit_once(' ').unwrap();
        let dpi_arguments: Vec<String> = arguments
            .trim_end_matches(')')
            .split(',')
            .map(|a| a.split_whitespace().collect::<Vec<_>>())
            .filter(|words| !words.is_empty())
            .map(|words| {
                let (direction, kind) = (words[0], words[1]);
                if direction == "output" {
                    format!("output {kind}")
                } else {
                    kind.to_string()
                }
            })
            .collect();
        let start = header
            .match_indices(&format!("{name}("))
            .map(|(i, _)| i)
            .find(|&i| !header[..i].ends_with(|c: char| c.is_ascii_alphanumeric() || c == '_'))
            .unwrap_or_else(|| panic!("{name} is not in gyrofx.h"));
        let c_return = header[..start]
            .rsplit([';', '{', '}'])
            .next()
            .unwrap()
            .trim()
            .to_string();
        let c_arguments = &header[start + name.len() + 1..];
        let c_arguments = &c_arguments[..c_arguments.find(')').unwrap()];
        let c_types: Vec<Option<String>> = c_arguments
            .split(',')
            .map(str::trim)
            .filter(|a| !a.is_empty() && *a != "void")
            .map(|a| {
                let cut = a.rfind([' ', '*']).unwrap();
                dpi_type_of(&a[..=cut])
            })
            .collect();
        assert_eq!(
            dpi_type_of(&c_return).as_deref(),
            Some(return_type),
            "{name}: returns {c_return} in C"
        );
        let want: Vec<Option<String>> = dpi_arguments.into_iter().map(Some).collect();
        assert_eq!(c_types, want, "{name}: arguments ({c_arguments}) in C");
        checked += 1;
    }
    assert!(checked >= 30, "only {checked} imports in the package");
}

/// `scripts/install-capi.sh` installs the library, the header and a pkg-config file under a
/// prefix, all or nothing (a run stopped before its renames leaves no file and no folder);
/// `pkg-config` then gives the flags that build `check_api.c` against the installed copy,
/// which runs. A second install over it is refused without `--force`.
#[test]
fn the_installed_library_builds_a_c_program_through_pkg_config() {
    let dir = tempfile::tempdir().unwrap();
    let prefix = dir.path().join("prefix");
    let from = library().parent().unwrap().to_path_buf();
    let script = repository().join("scripts/install-capi.sh");
    let install = |extra: &[&str]| {
        let mut command = Command::new(&script);
        command.arg(&prefix).arg("--from").arg(&from).args(extra);
        text(&command.output().unwrap())
    };
    // A run stopped after staging every file leaves nothing behind: no file, no folder.
    let mut failing = Command::new(&script);
    failing
        .arg(&prefix)
        .arg("--from")
        .arg(&from)
        .env("GYROFX_INSTALL_FAIL_BEFORE_RENAME", "1");
    let failed = failing.output().unwrap();
    assert!(!failed.status.success(), "{}", text(&failed));
    assert!(!prefix.exists(), "{}: {}", prefix.display(), text(&failed));
    let log = install(&[]);
    assert!(log.contains("installed gyrofx_capi"), "{log}");
    assert!(prefix.join("include/gyrofx.h").is_file());
    let refused = install(&[]);
    assert!(
        refused.contains("exists; remove it or pass --force"),
        "{refused}"
    );
    assert!(install(&["--force"]).contains("installed gyrofx_capi"));
    let flags = Command::new("pkg-config")
        .args(["--cflags", "--libs", "--static", "gyrofx_capi"])
        .env("PKG_CONFIG_PATH", prefix.join("lib/pkgconfig"))
        .output()
        .expect("pkg-config runs (scripts/test.sh installs it)");
    assert!(flags.status.success(), "{}", text(&flags));
    let flags = String::from_utf8(flags.stdout).unwrap();
    assert!(
        flags.contains(&format!("-I{}", prefix.join("include").display())),
        "{flags}"
    );
    let program = dir.path().join("check_api");
    let mut gcc = Command::new("gcc");
    gcc.args(["-std=c99", "-Wall", "-Werror"])
        .arg(repository().join("capi/examples/check_api.c"))
        .args(flags.split_whitespace())
        .arg("-o")
        .arg(&program);
    let built = gcc.output().unwrap();
    assert!(built.status.success(), "{}", text(&built));
    let ran = Command::new(&program)
        .env("LD_LIBRARY_PATH", prefix.join("lib"))
        .output()
        .unwrap();
    assert!(ran.status.success(), "{}", text(&ran));
    assert!(text(&ran).contains("pipeline kf 4 3"), "{}", text(&ran));

    // The README's and examples/c's program, built the same way: it prints the Rust model's
    // code for the same sample, and the refusal of a code outside the input format.
    let example = dir.path().join("kf_step");
    let built = Command::new("gcc")
        .args(["-std=c99", "-Wall", "-Werror"])
        .arg(repository().join("examples/c/kf_step.c"))
        .args(flags.split_whitespace())
        .arg("-o")
        .arg(&example)
        .output()
        .unwrap();
    assert!(built.status.success(), "{}", text(&built));
    let ran = Command::new(&example)
        .env("LD_LIBRARY_PATH", prefix.join("lib"))
        .output()
        .unwrap();
    let job = gyrofx_job::job::Job::new(gyrofx_job::config::Config::embedded()).unwrap();
    let want = gyrofx_job::golden::Kf::new(&job.chain.kf)
        .step(1000, 0)
        .unwrap();
    let log = text(&ran);
    assert!(ran.status.success(), "{log}");
    assert!(log.contains(&format!("rate_out = {want}\n")), "{log}");
    assert!(
        log.contains("refused: z = 1099511627776 is not a code of"),
        "{log}"
    );
}
