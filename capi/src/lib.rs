//! gyrofx's bit-accurate model behind a C ABI, for C and C++ testbenches (a Verilator harness)
//! and SystemVerilog through DPI-C. The header is `capi/include/gyrofx.h` (cbindgen; a test
//! keeps it equal to the code).
//!
//! Every block wraps [`gyrofx_job::golden`]: the same model as the vectors, codes in and out
//! exactly as the RTL ports carry them (`int64_t` two's-complement values, flags 0/1, a mode 1
//! normal / 0 reverse). The signatures keep to DPI-C's types (`chandle` = pointer, `longint` =
//! `int64_t`, `int` = `int32_t`, `string` = `const char *`) so a SystemVerilog testbench imports
//! them as they are.
//!
//! Ownership: every `gyrofx_*_new` / `gyrofx_plan_*` result is freed by its `gyrofx_*_free`
//! (NULL is accepted and ignored). Errors: a constructor returns NULL and a step returns -1;
//! `gyrofx_last_error()` then holds the message (the CLI's, naming the port or config field,
//! the value and what is allowed), valid until the thread's next failing call. Nothing here
//! panics across the boundary; a handle is used by one thread at a time.
//!
//! The calls as C makes them (here from Rust, as the crate's `rlib`):
//!
//! ```
//! use gyrofx_capi::*;
//!
//! let plan = gyrofx_plan_default();
//! let kf = unsafe { gyrofx_kf_new(plan) };
//! let mut rate_out = 0i64;
//! assert_eq!(unsafe { gyrofx_kf_step(kf, 1000, 0, &mut rate_out) }, 0);
//! assert_eq!(unsafe { gyrofx_kf_step(kf, 1 << 40, 0, &mut rate_out) }, -1); // refused
//! let mut message = [0 as std::ffi::c_char; 128];
//! unsafe { gyrofx_last_error_copy(message.as_mut_ptr(), message.len() as i32) };
//! let text = unsafe { std::ffi::CStr::from_ptr(message.as_ptr()) }.to_string_lossy();
//! assert!(text.starts_with("z = 1099511627776 is not a code of"));
//! unsafe {
//!     gyrofx_kf_free(kf);
//!     gyrofx_plan_free(plan);
//! }
//! ```

#![allow(unsafe_code)]

use std::cell::RefCell;
use std::collections::BTreeMap;
use std::ffi::{c_char, CStr, CString};
use std::path::Path;
use std::sync::Mutex;

use gyrofx_job::config::Config;
use gyrofx_job::golden::{self, ports::Port};
use gyrofx_job::job::Job;
use gyrofx_job::pipeline::{self, Pipeline};

thread_local! {
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

fn fail(message: impl std::fmt::Display) {
    let text = message.to_string().replace('\0', " ");
    LAST_ERROR.with(|e| *e.borrow_mut() = CString::new(text).unwrap_or_default());
}

/// The message of the calling thread's last failure ("" before any). The text belongs to the
/// library and stays valid only until the thread's next failing call, which frees it: read or
/// copy it before calling again (`gyrofx_last_error_copy` copies it into a buffer of yours).
#[no_mangle]
pub extern "C" fn gyrofx_last_error() -> *const c_char {
    LAST_ERROR.with(|e| e.borrow().as_ptr())
}

/// Copies the calling thread's last failure message into `buffer` (`size` bytes), cut to fit
/// and always NUL-terminated when `size` > 0, as `snprintf` does. Returns the message's full
/// length in bytes (without the NUL; a return >= `size` means it was cut), or -1 when `buffer`
/// is NULL with `size` > 0 or `size` < 0. The copy is the caller's: later calls leave it alone.
///
/// # Safety
/// `buffer` is NULL or writable for `size` bytes.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_last_error_copy(buffer: *mut c_char, size: i32) -> i32 {
    let Ok(size) = usize::try_from(size) else {
        return -1;
    };
    if buffer.is_null() && size > 0 {
        return -1;
    }
    LAST_ERROR.with(|e| {
        let message = e.borrow();
        let bytes = message.as_bytes();
        if size > 0 {
            let copied = bytes.len().min(size - 1);
            // SAFETY: `buffer` is writable for `size` > `copied` bytes, by contract; the
            // message is the library's own allocation, so the two do not overlap.
            unsafe {
                std::ptr::copy_nonoverlapping(bytes.as_ptr().cast::<c_char>(), buffer, copied);
                *buffer.add(copied) = 0;
            }
        }
        i32::try_from(bytes.len()).unwrap_or(i32::MAX)
    })
}

/// The library's version ("0.1.0"), static.
#[no_mangle]
pub extern "C" fn gyrofx_version() -> *const c_char {
    concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr().cast()
}

/// A resolved config (the embedded default overlaid by a TOML text, a file or a package's
/// manifest), as `gyrofx generate` resolves it.
pub struct GyrofxPlan {
    job: Job,
}

/// Reads a C string argument, failing with the argument's name when it is NULL or not UTF-8.
///
/// # Safety
/// `text` is NULL or a NUL-terminated string.
unsafe fn text<'a>(text: *const c_char, what: &str) -> Option<&'a str> {
    if text.is_null() {
        fail(format!("{what} is NULL"));
        return None;
    }
    // SAFETY: non-NULL and NUL-terminated by the caller's contract.
    match unsafe { CStr::from_ptr(text) }.to_str() {
        Ok(text) => Some(text),
        Err(_) => {
            fail(format!("{what} is not UTF-8"));
            None
        }
    }
}

fn plan(config: gyrofx_job::error::Result<Config>) -> *mut GyrofxPlan {
    match config.and_then(Job::new) {
        Ok(job) => Box::into_raw(Box::new(GyrofxPlan { job })),
        Err(e) => {
            fail(e);
            std::ptr::null_mut()
        }
    }
}

/// The embedded default config.
#[no_mangle]
pub extern "C" fn gyrofx_plan_default() -> *mut GyrofxPlan {
    plan(Ok(Config::embedded()))
}

/// A (partial) TOML config over the default; NULL on an error.
///
/// # Safety
/// `toml` is NULL or a NUL-terminated string.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_plan_from_toml(toml: *const c_char) -> *mut GyrofxPlan {
    // SAFETY: forwarded contract.
    match unsafe { text(toml, "toml") } {
        Some(toml) => plan(Config::from_toml(toml, "<toml text>")),
        None => std::ptr::null_mut(),
    }
}

/// A config file over the default (as `--config`); NULL on an error.
///
/// # Safety
/// `path` is NULL or a NUL-terminated string.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_plan_from_file(path: *const c_char) -> *mut GyrofxPlan {
    // SAFETY: forwarded contract.
    match unsafe { text(path, "path") } {
        Some(path) => plan(Config::from_file(Path::new(path))),
        None => std::ptr::null_mut(),
    }
}

/// The config a generated package was made from (`<folder>/manifest.json`); NULL on an error.
///
/// # Safety
/// `folder` is NULL or a NUL-terminated string.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_plan_from_package(folder: *const c_char) -> *mut GyrofxPlan {
    // SAFETY: forwarded contract.
    match unsafe { text(folder, "folder") } {
        Some(folder) => plan(gyrofx_job::config::Config::from_package(Path::new(folder))),
        None => std::ptr::null_mut(),
    }
}

/// Frees a plan (blocks made from it stay valid: they hold their own copy).
///
/// # Safety
/// `plan` is NULL or a pointer from a `gyrofx_plan_*` function, not freed before.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_plan_free(plan: *mut GyrofxPlan) {
    if !plan.is_null() {
        // SAFETY: made by Box::into_raw and not freed before, by contract.
        drop(unsafe { Box::from_raw(plan) });
    }
}

/// Frees a block made by one of the `gyrofx_*_new` functions.
///
/// # Safety
/// `block` is NULL or from `Box::into_raw` of a `T`, not freed before.
unsafe fn free<T>(block: *mut T) {
    if !block.is_null() {
        // SAFETY: by contract.
        drop(unsafe { Box::from_raw(block) });
    }
}

/// A block made from a plan, or NULL (with the error) when the plan is NULL.
///
/// # Safety
/// `plan` is NULL or a live plan.
unsafe fn new<T>(plan: *const GyrofxPlan, make: impl FnOnce(&Job) -> T) -> *mut T {
    // SAFETY: NULL or live, by contract.
    match unsafe { plan.as_ref() } {
        Some(plan) => Box::into_raw(Box::new(make(&plan.job))),
        None => {
            fail("plan is NULL");
            std::ptr::null_mut()
        }
    }
}

/// Runs `step` on a live block, storing the error; 0 or -1.
///
/// # Safety
/// `block` is NULL or a live block of type `T`.
unsafe fn with<T>(block: *mut T, step: impl FnOnce(&mut T) -> golden::PortResult<()>) -> i32 {
    // SAFETY: NULL or live and not shared across threads, by contract.
    let Some(block) = (unsafe { block.as_mut() }) else {
        fail("block is NULL");
        return -1;
    };
    match step(block) {
        Ok(()) => 0,
        Err(message) => {
            fail(message);
            -1
        }
    }
}

/// Writes `value` through `out` when it is not NULL.
///
/// # Safety
/// `out` is NULL or valid for a write.
unsafe fn put<V>(out: *mut V, value: V) {
    // SAFETY: by contract.
    if let Some(out) = unsafe { out.as_mut() } {
        *out = value;
    }
}

/// A live block to read, or None with "block is NULL" as the thread's error.
///
/// # Safety
/// `block` is NULL or a live block of type `T`.
unsafe fn live<'a, T>(block: *const T) -> Option<&'a T> {
    // SAFETY: NULL or live, by contract.
    let block = unsafe { block.as_ref() };
    if block.is_none() {
        fail("block is NULL");
    }
    block
}

/// A count or width as DPI-C's `int`.
fn int(n: impl TryInto<i32>) -> i32 {
    n.try_into().unwrap_or(i32::MAX)
}

/// Writes a live block's pipeline through the two outputs (each NULL or writable); 0, or -1
/// for a NULL block.
///
/// # Safety
/// `block` is NULL or a live block of type `T`; each output NULL or writable.
unsafe fn pipeline_of<T>(
    block: *const T,
    pipeline: impl FnOnce(&T) -> Pipeline,
    latency_clocks: *mut i32,
    min_clocks_per_sample: *mut i32,
) -> i32 {
    // SAFETY: forwarded contract.
    let Some(block) = (unsafe { live(block) }) else {
        return -1;
    };
    let pipeline = pipeline(block);
    // SAFETY: forwarded contract.
    unsafe {
        put(latency_clocks, int(pipeline.latency_clocks));
        put(min_clocks_per_sample, int(pipeline.min_clocks_per_sample));
    }
    0
}

/// A port name as a C string that lives as long as the library: each name is made once and
/// kept (the names are a fixed, small set).
fn c_name(name: &'static str) -> *const c_char {
    static NAMES: Mutex<BTreeMap<&'static str, CString>> = Mutex::new(BTreeMap::new());
    let mut names = NAMES
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    names
        .entry(name)
        .or_insert_with(|| CString::new(name).unwrap_or_default())
        .as_ptr()
}

/// How many ports a live block has; -1 for a NULL block.
///
/// # Safety
/// `block` is NULL or a live block of type `T`.
unsafe fn port_count_of<T>(block: *const T, ports: impl FnOnce(&T) -> Vec<Port>) -> i32 {
    // SAFETY: forwarded contract.
    unsafe { live(block) }.map_or(-1, |block| int(ports(block).len()))
}

/// Writes port `index` of a live block (the vector files' order: inputs, then outputs):
/// its name (a string the library keeps), width, fraction bits, whether it is signed and
/// whether it is an output. 0, or -1 for a NULL block or an index out of range.
///
/// # Safety
/// `block` is NULL or a live block of type `T`; each output NULL or writable.
unsafe fn port_of<T>(
    block: *const T,
    ports: impl FnOnce(&T) -> Vec<Port>,
    index: i32,
    outputs: PortOutputs,
) -> i32 {
    // SAFETY: forwarded contract.
    let Some(block) = (unsafe { live(block) }) else {
        return -1;
    };
    let ports = ports(block);
    let Some(port) = usize::try_from(index).ok().and_then(|i| ports.get(i)) else {
        fail(format!(
            "port index = {index}: allowed 0 to {} (the block has {} ports)",
            ports.len() - 1,
            ports.len()
        ));
        return -1;
    };
    // SAFETY: forwarded contract.
    unsafe {
        put(outputs.name, c_name(port.name));
        put(outputs.width, int(port.format.width));
        put(outputs.fraction, port.format.frac);
        put(outputs.is_signed, i32::from(port.format.signed));
        put(outputs.is_output, i32::from(port.output));
    }
    0
}

/// Where [`port_of`] writes a port's facts.
struct PortOutputs {
    name: *mut *const c_char,
    width: *mut i32,
    fraction: *mut i32,
    is_signed: *mut i32,
    is_output: *mut i32,
}

/// The steady-state KF (`gyrofx_kf`).
pub struct GyrofxKf(golden::Kf, Pipeline);

/// A KF from reset; NULL when `plan` is NULL.
///
/// # Safety
/// `plan` is NULL or a live plan.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_kf_new(plan: *const GyrofxPlan) -> *mut GyrofxKf {
    // SAFETY: forwarded contract.
    unsafe {
        new(plan, |job| {
            GyrofxKf(golden::Kf::new(job.kf()), pipeline::KF)
        })
    }
}

/// Frees a KF.
///
/// # Safety
/// `kf` is NULL or from `gyrofx_kf_new`, not freed before.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_kf_free(kf: *mut GyrofxKf) {
    // SAFETY: forwarded contract.
    unsafe { free(kf) }
}

/// The RTL pipeline of the KF, as the package's manifest and testbenches have it: writes the clocks
/// from a sample's `ce` to its registered outputs and the fewest clocks from one sample's `ce` to
/// the next one's (the RTL's simulation stops on a faster stream). Returns 0, or -1 for a NULL
/// handle.
///
/// # Safety
/// `kf` is NULL or live; each output NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_kf_pipeline(
    kf: *const GyrofxKf,
    latency_clocks: *mut i32,
    min_clocks_per_sample: *mut i32,
) -> i32 {
    // SAFETY: forwarded contract.
    unsafe { pipeline_of(kf, |b| b.1, latency_clocks, min_clocks_per_sample) }
}

/// How many ports the KF has (after `clk`, `rst` and `ce`; see `gyrofx_kf_port`),
/// or -1 for a NULL handle.
///
/// # Safety
/// `kf` is NULL or live.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_kf_port_count(kf: *const GyrofxKf) -> i32 {
    // SAFETY: forwarded contract.
    unsafe { port_count_of(kf, |b| b.0.ports()) }
}

/// Port `index` of the KF, in its vector files' order (inputs, then outputs): writes its
/// name (a string the library keeps: do not free it), its format's width and fraction bits,
/// whether it is signed and whether it is an output. Returns 0, or -1 for a NULL handle or
/// an index out of range (`gyrofx_last_error()` says which are allowed).
///
/// # Safety
/// `kf` is NULL or live; each output NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_kf_port(
    kf: *const GyrofxKf,
    index: i32,
    name: *mut *const c_char,
    width: *mut i32,
    fraction: *mut i32,
    is_signed: *mut i32,
    is_output: *mut i32,
) -> i32 {
    let outputs = PortOutputs {
        name,
        width,
        fraction,
        is_signed,
        is_output,
    };
    // SAFETY: forwarded contract.
    unsafe { port_of(kf, |b| b.0.ports(), index, outputs) }
}

/// The synchronous reset. Returns 0, or -1 for a NULL handle.
///
/// # Safety
/// `kf` is NULL or live.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_kf_reset(kf: *mut GyrofxKf) -> i32 {
    // SAFETY: forwarded contract.
    unsafe {
        with(kf, |kf| {
            kf.0.reset();
            Ok(())
        })
    }
}

/// One sample: `z` (input-format code) and `bw_sel`; writes `rate_out`. Returns 0, or -1 for
/// a refused input (state unchanged; `gyrofx_last_error()` says why).
///
/// # Safety
/// `kf` is NULL or live; `rate_out` NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_kf_step(
    kf: *mut GyrofxKf,
    z: i64,
    bw_sel: i32,
    rate_out: *mut i64,
) -> i32 {
    // SAFETY: forwarded contract.
    unsafe {
        with(kf, |kf| {
            let rate = kf.0.step(z, i64::from(bw_sel))?;
            put(rate_out, rate);
            Ok(())
        })
    }
}

/// The mode-reversal sequencer (`gyrofx_sequencer`).
pub struct GyrofxSequencer(golden::Sequencer, Pipeline);

/// A sequencer from reset; NULL when `plan` is NULL.
///
/// # Safety
/// `plan` is NULL or a live plan.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_sequencer_new(plan: *const GyrofxPlan) -> *mut GyrofxSequencer {
    // SAFETY: forwarded contract.
    unsafe {
        new(plan, |job| {
            GyrofxSequencer(
                golden::Sequencer::new(&job.chain.estimator.schedule),
                pipeline::SEQUENCER,
            )
        })
    }
}

/// Frees a sequencer.
///
/// # Safety
/// `sequencer` is NULL or from `gyrofx_sequencer_new`, not freed before.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_sequencer_free(sequencer: *mut GyrofxSequencer) {
    // SAFETY: forwarded contract.
    unsafe { free(sequencer) }
}

/// The RTL pipeline of the sequencer, as the package's manifest and testbenches have it: writes the
/// clocks from a sample's `ce` to its registered outputs and the fewest clocks from one sample's
/// `ce` to the next one's (the RTL's simulation stops on a faster stream). Returns 0, or -1 for a
/// NULL handle.
///
/// # Safety
/// `sequencer` is NULL or live; each output NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_sequencer_pipeline(
    sequencer: *const GyrofxSequencer,
    latency_clocks: *mut i32,
    min_clocks_per_sample: *mut i32,
) -> i32 {
    // SAFETY: forwarded contract.
    unsafe { pipeline_of(sequencer, |b| b.1, latency_clocks, min_clocks_per_sample) }
}

/// How many ports the sequencer has (after `clk`, `rst` and `ce`; see `gyrofx_sequencer_port`),
/// or -1 for a NULL handle.
///
/// # Safety
/// `sequencer` is NULL or live.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_sequencer_port_count(sequencer: *const GyrofxSequencer) -> i32 {
    // SAFETY: forwarded contract.
    unsafe { port_count_of(sequencer, |b| b.0.ports()) }
}

/// Port `index` of the sequencer, in its vector files' order (inputs, then outputs): writes its
/// name (a string the library keeps: do not free it), its format's width and fraction bits,
/// whether it is signed and whether it is an output. Returns 0, or -1 for a NULL handle or
/// an index out of range (`gyrofx_last_error()` says which are allowed).
///
/// # Safety
/// `sequencer` is NULL or live; each output NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_sequencer_port(
    sequencer: *const GyrofxSequencer,
    index: i32,
    name: *mut *const c_char,
    width: *mut i32,
    fraction: *mut i32,
    is_signed: *mut i32,
    is_output: *mut i32,
) -> i32 {
    let outputs = PortOutputs {
        name,
        width,
        fraction,
        is_signed,
        is_output,
    };
    // SAFETY: forwarded contract.
    unsafe { port_of(sequencer, |b| b.0.ports(), index, outputs) }
}

/// The synchronous reset. Returns 0, or -1 for a NULL handle.
///
/// # Safety
/// `sequencer` is NULL or live.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_sequencer_reset(sequencer: *mut GyrofxSequencer) -> i32 {
    // SAFETY: forwarded contract.
    unsafe {
        with(sequencer, |s| {
            s.0.reset();
            Ok(())
        })
    }
}

/// One clock that takes a sample: writes this clock's (combinational) slot, then advances.
/// Returns 0, or -1 for a NULL handle.
///
/// # Safety
/// `sequencer` is NULL or live; each output NULL or writable.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn gyrofx_sequencer_step(
    sequencer: *mut GyrofxSequencer,
    mode_a: *mut i32,
    mode_b: *mut i32,
    blank_a: *mut i32,
    blank_b: *mut i32,
    interval_a: *mut i32,
    interval_b: *mut i32,
    done_a: *mut i32,
    done_b: *mut i32,
    window_done: *mut i32,
) -> i32 {
    // SAFETY: forwarded contract.
    unsafe {
        with(sequencer, |s| {
            let outputs = [
                mode_a,
                mode_b,
                blank_a,
                blank_b,
                interval_a,
                interval_b,
                done_a,
                done_b,
                window_done,
            ];
            for (out, code) in outputs.into_iter().zip(s.0.step()) {
                put(out, code as i32);
            }
            Ok(())
        })
    }
}

/// The least-squares bias estimator (`gyrofx_bias_estimator`).
pub struct GyrofxEstimator(golden::Estimator, Pipeline);

/// An estimator from reset; NULL when `plan` is NULL.
///
/// # Safety
/// `plan` is NULL or a live plan.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_estimator_new(plan: *const GyrofxPlan) -> *mut GyrofxEstimator {
    // SAFETY: forwarded contract.
    unsafe {
        new(plan, |job| {
            GyrofxEstimator(
                golden::Estimator::new(&job.chain.estimator),
                pipeline::ESTIMATOR,
            )
        })
    }
}

/// Frees an estimator.
///
/// # Safety
/// `estimator` is NULL or from `gyrofx_estimator_new`, not freed before.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_estimator_free(estimator: *mut GyrofxEstimator) {
    // SAFETY: forwarded contract.
    unsafe { free(estimator) }
}

/// The RTL pipeline of the estimator, as the package's manifest and testbenches have it: writes the
/// clocks from a sample's `ce` to its registered outputs and the fewest clocks from one sample's
/// `ce` to the next one's (the RTL's simulation stops on a faster stream). Returns 0, or -1 for a
/// NULL handle.
///
/// # Safety
/// `estimator` is NULL or live; each output NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_estimator_pipeline(
    estimator: *const GyrofxEstimator,
    latency_clocks: *mut i32,
    min_clocks_per_sample: *mut i32,
) -> i32 {
    // SAFETY: forwarded contract.
    unsafe { pipeline_of(estimator, |b| b.1, latency_clocks, min_clocks_per_sample) }
}

/// How many ports the estimator has (after `clk`, `rst` and `ce`; see `gyrofx_estimator_port`),
/// or -1 for a NULL handle.
///
/// # Safety
/// `estimator` is NULL or live.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_estimator_port_count(estimator: *const GyrofxEstimator) -> i32 {
    // SAFETY: forwarded contract.
    unsafe { port_count_of(estimator, |b| b.0.ports()) }
}

/// Port `index` of the estimator, in its vector files' order (inputs, then outputs): writes its
/// name (a string the library keeps: do not free it), its format's width and fraction bits,
/// whether it is signed and whether it is an output. Returns 0, or -1 for a NULL handle or
/// an index out of range (`gyrofx_last_error()` says which are allowed).
///
/// # Safety
/// `estimator` is NULL or live; each output NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_estimator_port(
    estimator: *const GyrofxEstimator,
    index: i32,
    name: *mut *const c_char,
    width: *mut i32,
    fraction: *mut i32,
    is_signed: *mut i32,
    is_output: *mut i32,
) -> i32 {
    let outputs = PortOutputs {
        name,
        width,
        fraction,
        is_signed,
        is_output,
    };
    // SAFETY: forwarded contract.
    unsafe { port_of(estimator, |b| b.0.ports(), index, outputs) }
}

/// The synchronous reset. Returns 0, or -1 for a NULL handle.
///
/// # Safety
/// `estimator` is NULL or live.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_estimator_reset(estimator: *mut GyrofxEstimator) -> i32 {
    // SAFETY: forwarded contract.
    unsafe {
        with(estimator, |e| {
            e.0.reset();
            Ok(())
        })
    }
}

/// One sample: both gyros' codes and the sequencer's slot; writes the registered outputs
/// after the clock. Returns 0, or -1 for a refused input.
///
/// # Safety
/// `estimator` is NULL or live; each output NULL or writable.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn gyrofx_estimator_step(
    estimator: *mut GyrofxEstimator,
    y_a: i64,
    y_b: i64,
    blank_a: i32,
    blank_b: i32,
    done_a: i32,
    done_b: i32,
    interval_a: i32,
    interval_b: i32,
    window_done: i32,
    bias_a: *mut i64,
    bias_b: *mut i64,
    estimated: *mut i32,
) -> i32 {
    let slot = [
        blank_a,
        blank_b,
        done_a,
        done_b,
        interval_a,
        interval_b,
        window_done,
    ]
    .map(i64::from);
    // SAFETY: forwarded contract.
    unsafe {
        with(estimator, |e| {
            let [a, b, done] = e.0.step([y_a, y_b], slot)?;
            put(bias_a, a);
            put(bias_b, b);
            put(estimated, done as i32);
            Ok(())
        })
    }
}

/// The mean filter with gross-error rejection (`gyrofx_mean_filter`).
pub struct GyrofxMeanFilter(golden::MeanFilter, Pipeline);

/// A mean filter from reset; NULL when `plan` is NULL.
///
/// # Safety
/// `plan` is NULL or a live plan.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_mean_filter_new(plan: *const GyrofxPlan) -> *mut GyrofxMeanFilter {
    // SAFETY: forwarded contract.
    unsafe {
        new(plan, |job| {
            GyrofxMeanFilter(
                golden::MeanFilter::new(&job.mean_filter),
                pipeline::mean_filter(job),
            )
        })
    }
}

/// Frees a mean filter.
///
/// # Safety
/// `filter` is NULL or from `gyrofx_mean_filter_new`, not freed before.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_mean_filter_free(filter: *mut GyrofxMeanFilter) {
    // SAFETY: forwarded contract.
    unsafe { free(filter) }
}

/// The RTL pipeline of the mean filter (as the plan's `architecture` builds it), as the package's
/// manifest and testbenches have it: writes the clocks from a sample's `ce` to its registered
/// outputs and the fewest clocks from one sample's `ce` to the next one's (the RTL's simulation
/// stops on a faster stream). Returns 0, or -1 for a NULL handle.
///
/// # Safety
/// `filter` is NULL or live; each output NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_mean_filter_pipeline(
    filter: *const GyrofxMeanFilter,
    latency_clocks: *mut i32,
    min_clocks_per_sample: *mut i32,
) -> i32 {
    // SAFETY: forwarded contract.
    unsafe { pipeline_of(filter, |b| b.1, latency_clocks, min_clocks_per_sample) }
}

/// How many ports the mean filter has (after `clk`, `rst` and `ce`; see `gyrofx_mean_filter_port`),
/// or -1 for a NULL handle.
///
/// # Safety
/// `filter` is NULL or live.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_mean_filter_port_count(filter: *const GyrofxMeanFilter) -> i32 {
    // SAFETY: forwarded contract.
    unsafe { port_count_of(filter, |b| b.0.ports()) }
}

/// Port `index` of the mean filter, in its vector files' order (inputs, then outputs): writes its
/// name (a string the library keeps: do not free it), its format's width and fraction bits,
/// whether it is signed and whether it is an output. Returns 0, or -1 for a NULL handle or
/// an index out of range (`gyrofx_last_error()` says which are allowed).
///
/// # Safety
/// `filter` is NULL or live; each output NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_mean_filter_port(
    filter: *const GyrofxMeanFilter,
    index: i32,
    name: *mut *const c_char,
    width: *mut i32,
    fraction: *mut i32,
    is_signed: *mut i32,
    is_output: *mut i32,
) -> i32 {
    let outputs = PortOutputs {
        name,
        width,
        fraction,
        is_signed,
        is_output,
    };
    // SAFETY: forwarded contract.
    unsafe { port_of(filter, |b| b.0.ports(), index, outputs) }
}

/// The synchronous reset. Returns 0, or -1 for a NULL handle.
///
/// # Safety
/// `filter` is NULL or live.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_mean_filter_reset(filter: *mut GyrofxMeanFilter) -> i32 {
    // SAFETY: forwarded contract.
    unsafe {
        with(filter, |f| {
            f.0.reset();
            Ok(())
        })
    }
}

/// One sample `x`: writes `y_valid` and, on a block's last sample, `y` and `kept` (else 0).
/// Returns 0, or -1 for a refused input.
///
/// # Safety
/// `filter` is NULL or live; each output NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_mean_filter_step(
    filter: *mut GyrofxMeanFilter,
    x: i64,
    y_valid: *mut i32,
    y: *mut i64,
    kept: *mut i64,
) -> i32 {
    // SAFETY: forwarded contract.
    unsafe {
        with(filter, |f| {
            let (valid, mean, count) = match f.0.step(x)? {
                Some((mean, count)) => (1, mean, count),
                None => (0, 0, 0),
            };
            put(y_valid, valid);
            put(y, mean);
            put(kept, count);
            Ok(())
        })
    }
}

/// The whole chain (`gyrofx_top`).
pub struct GyrofxChain(golden::Chain, Pipeline);

/// A chain from reset; NULL when `plan` is NULL.
///
/// # Safety
/// `plan` is NULL or a live plan.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_chain_new(plan: *const GyrofxPlan) -> *mut GyrofxChain {
    // SAFETY: forwarded contract.
    unsafe {
        new(plan, |job| {
            GyrofxChain(golden::Chain::new(&job.chain), pipeline::top(job))
        })
    }
}

/// Frees a chain.
///
/// # Safety
/// `chain` is NULL or from `gyrofx_chain_new`, not freed before.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_chain_free(chain: *mut GyrofxChain) {
    // SAFETY: forwarded contract.
    unsafe { free(chain) }
}

/// The RTL pipeline of the chain (`gyrofx_top`, or `gyrofx_top_serial` with `architecture =
/// "serial"`), as the package's manifest and testbenches have it: writes the clocks from a sample's
/// `ce` to its registered outputs and the fewest clocks from one sample's `ce` to the next one's
/// (the RTL's simulation stops on a faster stream). Returns 0, or -1 for a NULL handle.
///
/// # Safety
/// `chain` is NULL or live; each output NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_chain_pipeline(
    chain: *const GyrofxChain,
    latency_clocks: *mut i32,
    min_clocks_per_sample: *mut i32,
) -> i32 {
    // SAFETY: forwarded contract.
    unsafe { pipeline_of(chain, |b| b.1, latency_clocks, min_clocks_per_sample) }
}

/// How many ports the chain has (after `clk`, `rst` and `ce`; see `gyrofx_chain_port`),
/// or -1 for a NULL handle.
///
/// # Safety
/// `chain` is NULL or live.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_chain_port_count(chain: *const GyrofxChain) -> i32 {
    // SAFETY: forwarded contract.
    unsafe { port_count_of(chain, |b| b.0.ports()) }
}

/// Port `index` of the chain, in its vector files' order (inputs, then outputs): writes its
/// name (a string the library keeps: do not free it), its format's width and fraction bits,
/// whether it is signed and whether it is an output. Returns 0, or -1 for a NULL handle or
/// an index out of range (`gyrofx_last_error()` says which are allowed).
///
/// # Safety
/// `chain` is NULL or live; each output NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_chain_port(
    chain: *const GyrofxChain,
    index: i32,
    name: *mut *const c_char,
    width: *mut i32,
    fraction: *mut i32,
    is_signed: *mut i32,
    is_output: *mut i32,
) -> i32 {
    let outputs = PortOutputs {
        name,
        width,
        fraction,
        is_signed,
        is_output,
    };
    // SAFETY: forwarded contract.
    unsafe { port_of(chain, |b| b.0.ports(), index, outputs) }
}

/// The synchronous reset. Returns 0, or -1 for a NULL handle.
///
/// # Safety
/// `chain` is NULL or live.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_chain_reset(chain: *mut GyrofxChain) -> i32 {
    // SAFETY: forwarded contract.
    unsafe {
        with(chain, |c| {
            c.0.reset();
            Ok(())
        })
    }
}

/// The modes (1 normal, 0 reverse) the next sample runs in. Returns 0, or -1 for NULL.
///
/// # Safety
/// `chain` is NULL or live; each output NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_chain_next_modes(
    chain: *mut GyrofxChain,
    mode_a: *mut i32,
    mode_b: *mut i32,
) -> i32 {
    // SAFETY: forwarded contract.
    unsafe {
        with(chain, |c| {
            let [a, b] = c.0.next_modes();
            put(mode_a, a as i32);
            put(mode_b, b as i32);
            Ok(())
        })
    }
}

/// One sample: both gyros' codes and `bw_sel`; writes the output ports (`rate_out` 0 where
/// `out_valid` is 0). Returns 0, or -1 for a refused input.
///
/// # Safety
/// `chain` is NULL or live; each output NULL or writable.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn gyrofx_chain_step(
    chain: *mut GyrofxChain,
    y_a: i64,
    y_b: i64,
    bw_sel: i32,
    mode_a: *mut i32,
    mode_b: *mut i32,
    out_valid: *mut i32,
    rate_out: *mut i64,
    bias_a: *mut i64,
    bias_b: *mut i64,
    estimated: *mut i32,
) -> i32 {
    // SAFETY: forwarded contract.
    unsafe {
        with(chain, |c| {
            let [ma, mb, valid, rate, a, b, done] = c.0.step(y_a, y_b, i64::from(bw_sel))?;
            put(mode_a, ma as i32);
            put(mode_b, mb as i32);
            put(out_valid, valid as i32);
            put(rate_out, rate);
            put(bias_a, a);
            put(bias_b, b);
            put(estimated, done as i32);
            Ok(())
        })
    }
}

/// One gyro's digital loop (`gyrofx_gyro_loop`).
pub struct GyrofxGyroLoop(golden::GyroLoop, Pipeline);

/// Gyro `gyro`'s loop (0: A, whose plan the block's vectors and RTL parameters use; 1: B) from
/// reset; NULL when `plan` is NULL or `gyro` is neither.
///
/// # Safety
/// `plan` is NULL or a live plan.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_gyro_loop_new(
    plan: *const GyrofxPlan,
    gyro: i32,
) -> *mut GyrofxGyroLoop {
    let Ok(index @ 0..=1) = usize::try_from(gyro) else {
        fail(format!("gyro = {gyro}: allowed 0 (A) or 1 (B)"));
        return std::ptr::null_mut();
    };
    // SAFETY: forwarded contract.
    unsafe {
        new(plan, |job| {
            GyrofxGyroLoop(
                golden::GyroLoop::new(&job.gyro_loops[index].plan),
                pipeline::gyro_loop(job),
            )
        })
    }
}

/// Frees a loop.
///
/// # Safety
/// `gyro_loop` is NULL or from `gyrofx_gyro_loop_new`, not freed before.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_gyro_loop_free(gyro_loop: *mut GyrofxGyroLoop) {
    // SAFETY: forwarded contract.
    unsafe { free(gyro_loop) }
}

/// The RTL pipeline of the loop, as the package's manifest and testbenches have it: writes the
/// clocks from a sample's `ce` to its registered outputs and the fewest clocks from one sample's
/// `ce` to the next one's (the RTL's simulation stops on a faster stream). Returns 0, or -1 for a
/// NULL handle.
///
/// # Safety
/// `gyro_loop` is NULL or live; each output NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_gyro_loop_pipeline(
    gyro_loop: *const GyrofxGyroLoop,
    latency_clocks: *mut i32,
    min_clocks_per_sample: *mut i32,
) -> i32 {
    // SAFETY: forwarded contract.
    unsafe { pipeline_of(gyro_loop, |b| b.1, latency_clocks, min_clocks_per_sample) }
}

/// How many ports the loop has (after `clk`, `rst` and `ce`; see `gyrofx_gyro_loop_port`),
/// or -1 for a NULL handle.
///
/// # Safety
/// `gyro_loop` is NULL or live.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_gyro_loop_port_count(gyro_loop: *const GyrofxGyroLoop) -> i32 {
    // SAFETY: forwarded contract.
    unsafe { port_count_of(gyro_loop, |b| b.0.ports()) }
}

/// Port `index` of the loop, in its vector files' order (inputs, then outputs): writes its
/// name (a string the library keeps: do not free it), its format's width and fraction bits,
/// whether it is signed and whether it is an output. Returns 0, or -1 for a NULL handle or
/// an index out of range (`gyrofx_last_error()` says which are allowed).
///
/// # Safety
/// `gyro_loop` is NULL or live; each output NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_gyro_loop_port(
    gyro_loop: *const GyrofxGyroLoop,
    index: i32,
    name: *mut *const c_char,
    width: *mut i32,
    fraction: *mut i32,
    is_signed: *mut i32,
    is_output: *mut i32,
) -> i32 {
    let outputs = PortOutputs {
        name,
        width,
        fraction,
        is_signed,
        is_output,
    };
    // SAFETY: forwarded contract.
    unsafe { port_of(gyro_loop, |b| b.0.ports(), index, outputs) }
}

/// The synchronous reset. Returns 0, or -1 for a NULL handle.
///
/// # Safety
/// `gyro_loop` is NULL or live.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_gyro_loop_reset(gyro_loop: *mut GyrofxGyroLoop) -> i32 {
    // SAFETY: forwarded contract.
    unsafe {
        with(gyro_loop, |g| {
            g.0.reset();
            Ok(())
        })
    }
}

/// One ADC sample: both axes' ADC codes and `mode` (1 normal, 0 reverse); writes the output
/// ports (`rate` and `quadrature` hold their last values where `out_valid` is 0, as the RTL's
/// do). Returns 0, or -1 for a refused input.
///
/// # Safety
/// `gyro_loop` is NULL or live; each output NULL or writable.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn gyrofx_gyro_loop_step(
    gyro_loop: *mut GyrofxGyroLoop,
    adc_x: i64,
    adc_y: i64,
    mode: i32,
    dac_x: *mut i64,
    dac_y: *mut i64,
    locked: *mut i32,
    out_valid: *mut i32,
    rate: *mut i64,
    quadrature: *mut i64,
) -> i32 {
    // SAFETY: forwarded contract.
    unsafe {
        with(gyro_loop, |g| {
            let [x, y, lock, valid, r, q] = g.0.step(adc_x, adc_y, i64::from(mode))?;
            put(dac_x, x);
            put(dac_y, y);
            put(locked, lock as i32);
            put(out_valid, valid as i32);
            put(rate, r);
            put(quadrature, q);
            Ok(())
        })
    }
}

/// The whole gyro (`gyrofx_system`, or `gyrofx_system_serial` with `architecture = "serial"`:
/// the chain's outputs `gyrofx_job::pipeline::system_chain_delay` samples later): both loops and
/// the chain.
pub struct GyrofxSystem(golden::System, Pipeline);

/// The system from reset; NULL when `plan` is NULL or its plant has no system (the rate
/// plant).
///
/// # Safety
/// `plan` is NULL or a live plan.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_system_new(plan: *const GyrofxPlan) -> *mut GyrofxSystem {
    // SAFETY: NULL or live, by contract.
    if let Some(plan) = unsafe { plan.as_ref() } {
        if plan.job.system_chain.is_none() {
            fail(golden::NO_SYSTEM);
            return std::ptr::null_mut();
        }
    }
    // SAFETY: forwarded contract.
    unsafe {
        new(plan, |job| {
            GyrofxSystem(
                golden::System::of(job).expect("checked above"),
                pipeline::system(job),
            )
        })
    }
}

/// Frees a system.
///
/// # Safety
/// `system` is NULL or from `gyrofx_system_new`, not freed before.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_system_free(system: *mut GyrofxSystem) {
    // SAFETY: forwarded contract.
    unsafe { free(system) }
}

/// The RTL pipeline of the system, as the package's manifest and testbenches have it: writes the
/// clocks from a sample's `ce` to its registered outputs and the fewest clocks from one sample's
/// `ce` to the next one's (the RTL's simulation stops on a faster stream). Returns 0, or -1 for a
/// NULL handle.
///
/// # Safety
/// `system` is NULL or live; each output NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_system_pipeline(
    system: *const GyrofxSystem,
    latency_clocks: *mut i32,
    min_clocks_per_sample: *mut i32,
) -> i32 {
    // SAFETY: forwarded contract.
    unsafe { pipeline_of(system, |b| b.1, latency_clocks, min_clocks_per_sample) }
}

/// How many ports the system has (after `clk`, `rst` and `ce`; see `gyrofx_system_port`),
/// or -1 for a NULL handle.
///
/// # Safety
/// `system` is NULL or live.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_system_port_count(system: *const GyrofxSystem) -> i32 {
    // SAFETY: forwarded contract.
    unsafe { port_count_of(system, |b| b.0.ports()) }
}

/// Port `index` of the system, in its vector files' order (inputs, then outputs): writes its
/// name (a string the library keeps: do not free it), its format's width and fraction bits,
/// whether it is signed and whether it is an output. Returns 0, or -1 for a NULL handle or
/// an index out of range (`gyrofx_last_error()` says which are allowed).
///
/// # Safety
/// `system` is NULL or live; each output NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_system_port(
    system: *const GyrofxSystem,
    index: i32,
    name: *mut *const c_char,
    width: *mut i32,
    fraction: *mut i32,
    is_signed: *mut i32,
    is_output: *mut i32,
) -> i32 {
    let outputs = PortOutputs {
        name,
        width,
        fraction,
        is_signed,
        is_output,
    };
    // SAFETY: forwarded contract.
    unsafe { port_of(system, |b| b.0.ports(), index, outputs) }
}

/// The synchronous reset. Returns 0, or -1 for a NULL handle.
///
/// # Safety
/// `system` is NULL or live.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_system_reset(system: *mut GyrofxSystem) -> i32 {
    // SAFETY: forwarded contract.
    unsafe {
        with(system, |s| {
            s.0.reset();
            Ok(())
        })
    }
}

/// The modes (1 normal, 0 reverse) the loops take at the next sample if `enable` is 1 there.
/// Returns 0, or -1 for NULL.
///
/// # Safety
/// `system` is NULL or live; each output NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn gyrofx_system_next_modes(
    system: *mut GyrofxSystem,
    mode_a: *mut i32,
    mode_b: *mut i32,
) -> i32 {
    // SAFETY: forwarded contract.
    unsafe {
        with(system, |s| {
            let [a, b] = s.0.next_modes();
            put(mode_a, a as i32);
            put(mode_b, b as i32);
            Ok(())
        })
    }
}

/// One ADC sample: `enable`, `bw_sel` and both gyros' ADC codes; writes the output ports
/// (`mode_a`, `mode_b` the next sample's modes; `rate_out` holds its last value where
/// `out_valid` is 0, as the RTL's does). Returns 0, or -1 for a refused input.
///
/// # Safety
/// `system` is NULL or live; each output NULL or writable.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn gyrofx_system_step(
    system: *mut GyrofxSystem,
    enable: i32,
    bw_sel: i32,
    adc_a_x: i64,
    adc_a_y: i64,
    adc_b_x: i64,
    adc_b_y: i64,
    dac_a_x: *mut i64,
    dac_a_y: *mut i64,
    dac_b_x: *mut i64,
    dac_b_y: *mut i64,
    locked_a: *mut i32,
    locked_b: *mut i32,
    mode_a: *mut i32,
    mode_b: *mut i32,
    out_valid: *mut i32,
    rate_out: *mut i64,
    bias_a: *mut i64,
    bias_b: *mut i64,
    estimated: *mut i32,
) -> i32 {
    // SAFETY: forwarded contract.
    unsafe {
        with(system, |s| {
            let [ax, ay, bx, by, la, lb, ma, mb, valid, rate, ba, bb, done] = s.0.step(
                i64::from(enable),
                i64::from(bw_sel),
                [adc_a_x, adc_a_y, adc_b_x, adc_b_y],
            )?;
            put(dac_a_x, ax);
            put(dac_a_y, ay);
            put(dac_b_x, bx);
            put(dac_b_y, by);
            put(locked_a, la as i32);
            put(locked_b, lb as i32);
            put(mode_a, ma as i32);
            put(mode_b, mb as i32);
            put(out_valid, valid as i32);
            put(rate_out, rate);
            put(bias_a, ba);
            put(bias_b, bb);
            put(estimated, done as i32);
            Ok(())
        })
    }
}
