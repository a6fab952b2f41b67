//! Plots (plotters): the Allan deviation with its confidence intervals and fitted noise terms,
//! and the dynamic Allan deviation as a heatmap with the noise coefficients over time. PNG or
//! SVG by the file's extension.
//!
//! Lines are one pixel wide: plotters' thick-line rasterizer draws near-vertical segments
//! past their ends (seen in the DAVAR coefficient panels).
//!
//! Text needs a TrueType font: `GYROFX_FONT` if set, otherwise DejaVu Sans or Liberation Sans
//! from the usual system folders (Debian's `fonts-dejavu-core`, which `scripts/test.sh`
//! installs). Without one, plotting is refused with that advice.

use std::path::{Path, PathBuf};

use plotters::coord::Shift;
use plotters::prelude::*;

use gyrofx_model::analysis::allan::Kind;
use gyrofx_model::analysis::allan::Point;
use gyrofx_model::analysis::davar::{Coefficients, Davar};
use gyrofx_model::analysis::noise::{self, Terms};
use gyrofx_model::gyro_loop::trace::TracePoint;

use gyrofx_job::error::{Error, Result};

const FONT_PATHS: [&str; 6] = [
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation2/LiberationSans-Regular.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
    "/Library/Fonts/Arial.ttf",
];

/// Registers a TrueType font for plot text (once).
pub(crate) fn ensure_font() -> Result<()> {
    static FONT: std::sync::OnceLock<std::result::Result<(), String>> = std::sync::OnceLock::new();
    FONT.get_or_init(|| {
        let candidates: Vec<PathBuf> = std::env::var_os("GYROFX_FONT")
            .map(PathBuf::from)
            .into_iter()
            .chain(FONT_PATHS.iter().map(PathBuf::from))
            .collect();
        for path in &candidates {
            if let Ok(bytes) = std::fs::read(path) {
                let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
                if plotters::style::register_font("sans-serif", FontStyle::Normal, bytes).is_ok() {
                    return Ok(());
                }
            }
        }
        Err("plotting needs a TrueType font: set GYROFX_FONT to a .ttf file, or install one (apt-get install fonts-dejavu-core)".into())
    })
    .clone()
    .map_err(Error::Plot)
}

fn plot_error(path: &Path, e: impl std::fmt::Display) -> Error {
    Error::Plot(format!("plot {}: {e}", path.display()))
}

/// One series of an Allan plot.
pub struct AllanSeries<'a> {
    /// Legend label.
    pub label: String,
    /// The curve.
    pub points: &'a [Point],
    /// The fitted terms and the kind of deviation they were fitted to, drawn as lines.
    pub terms: Option<(&'a Terms, Kind)>,
}

const COLORS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
];

fn draw_allan<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    series: &[AllanSeries],
    title: &str,
) -> std::result::Result<(), String> {
    let e = |x: &dyn std::fmt::Display| x.to_string();
    area.fill(&WHITE).map_err(|x| e(&x))?;
    // A log scale needs positive values.
    let positive = |p: &&Point| p.dev > 0.0 && p.lo > 0.0 && p.dev.is_finite() && p.hi.is_finite();
    let all = series.iter().flat_map(|s| s.points.iter()).filter(positive);
    let (mut tmin, mut tmax, mut dmin, mut dmax) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    let mut any = false;
    for p in all {
        any = true;
        tmin = tmin.min(p.tau_s);
        tmax = tmax.max(p.tau_s);
        dmin = dmin.min(p.lo.max(p.dev * 1e-3));
        dmax = dmax.max(p.hi);
    }
    if !any {
        return Err("every deviation is zero or not finite (a constant record?): nothing to plot on a log scale".into());
    }
    if tmin >= tmax {
        tmax = tmin * 10.0;
    }
    if dmin >= dmax {
        dmax = dmin * 10.0;
    }
    let mut chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 24))
        .margin(12)
        .x_label_area_size(48)
        .y_label_area_size(80)
        .build_cartesian_2d(
            (tmin / 1.5..tmax * 1.5).log_scale(),
            (dmin / 2.0..dmax * 2.0).log_scale(),
        )
        .map_err(|x| e(&x))?;
    chart
        .configure_mesh()
        .x_desc("τ (s)")
        .y_desc("σ(τ) (°/s)")
        .x_label_formatter(&|v| format!("{v:.0e}"))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .draw()
        .map_err(|x| e(&x))?;
    for (i, s) in series.iter().enumerate() {
        let color = COLORS[i % COLORS.len()];
        chart
            .draw_series(
                s.points
                    .iter()
                    .filter(positive)
                    .map(|p| ErrorBar::new_vertical(p.tau_s, p.lo, p.dev, p.hi, color.filled(), 6)),
            )
            .map_err(|x| e(&x))?;
        chart
            .draw_series(LineSeries::new(
                s.points.iter().filter(positive).map(|p| (p.tau_s, p.dev)),
                color.stroke_width(1),
            ))
            .map_err(|x| e(&x))?
            .label(s.label.clone())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(1))
            });
        if let Some((t, kind)) = s.terms {
            let taus: Vec<f64> = (0..=60)
                .map(|k| tmin * (tmax / tmin).powf(k as f64 / 60.0))
                .collect();
            // The sample interval, for the modified deviation's factor-dependent terms.
            let tau0 = s
                .points
                .first()
                .map_or(1.0, |p| p.tau_s / p.m.max(1) as f64);
            let shape = |j: usize, tau: f64| {
                let m = (tau / tau0).round().max(1.0) as usize;
                noise::basis(kind, tau, m)[j]
            };
            let values = [t.q.value, t.n.value, t.b.value, t.k.value, t.r.value];
            let terms: Vec<(usize, f64)> = values
                .iter()
                .copied()
                .enumerate()
                .filter(|(_, v)| *v > 0.0)
                .collect();
            for (j, value) in &terms {
                chart
                    .draw_series(LineSeries::new(
                        taus.iter()
                            .map(|tau| (*tau, value * shape(*j, *tau).sqrt())),
                        color.mix(0.35).stroke_width(1),
                    ))
                    .map_err(|x| e(&x))?;
            }
            chart
                .draw_series(LineSeries::new(
                    taus.iter().map(|tau| {
                        let total: f64 = terms.iter().map(|(j, v)| v * v * shape(*j, *tau)).sum();
                        (*tau, total.sqrt())
                    }),
                    color.mix(0.6).stroke_width(1),
                ))
                .map_err(|x| e(&x))?;
        }
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .label_font(("sans-serif", 16))
        .draw()
        .map_err(|x| e(&x))?;
    area.present().map_err(|x| e(&x))
}

fn draw_davar<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    d: &Davar,
    c: &Coefficients,
) -> std::result::Result<(), String> {
    let e = |x: &dyn std::fmt::Display| x.to_string();
    area.fill(&WHITE).map_err(|x| e(&x))?;
    let (top, bottom) = area.split_vertically(area.dim_in_pixel().1 * 3 / 5);
    let (t0, t1) = (d.time_s[0], *d.time_s.last().unwrap_or(&d.time_s[0]));
    let t1 = if t1 > t0 { t1 } else { t0 + 1.0 };
    let values: Vec<f64> = d
        .adev
        .iter()
        .flatten()
        .flatten()
        .copied()
        .filter(|v| *v > 0.0 && v.is_finite())
        .collect();
    if values.is_empty() {
        return Err("every deviation is zero (a constant record?): nothing to plot".into());
    }
    let (lo, hi) = values.iter().fold((f64::MAX, f64::MIN), |(a, b), v| {
        (a.min(v.log10()), b.max(v.log10()))
    });
    let span = (hi - lo).max(1e-9);
    let mut chart = ChartBuilder::on(&top)
        .caption(
            "Dynamic Allan deviation (colour: log10 σ)",
            ("sans-serif", 22),
        )
        .margin(10)
        .x_label_area_size(36)
        .y_label_area_size(70)
        .build_cartesian_2d(t0..t1, 0..d.tau_s.len())
        .map_err(|x| e(&x))?;
    let tau_labels = d.tau_s.clone();
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc("time (s)")
        .y_desc("τ (s)")
        .y_label_formatter(&|j| {
            tau_labels
                .get(*j)
                .map(|t| format!("{t:.2e}"))
                .unwrap_or_default()
        })
        .draw()
        .map_err(|x| e(&x))?;
    let dt = if d.time_s.len() > 1 {
        d.time_s[1] - d.time_s[0]
    } else {
        t1 - t0
    };
    for (i, row) in d.adev.iter().enumerate() {
        for (j, v) in row.iter().enumerate() {
            if let Some(v) = v.filter(|v| *v > 0.0) {
                let x = (v.log10() - lo) / span;
                let color = HSLColor(0.7 * (1.0 - x), 0.9, 0.5);
                chart
                    .draw_series(std::iter::once(Rectangle::new(
                        [(d.time_s[i] - dt / 2.0, j), (d.time_s[i] + dt / 2.0, j + 1)],
                        color.filled(),
                    )))
                    .map_err(|x| e(&x))?;
            }
        }
    }
    let series: [(&str, &Vec<f64>); 3] = [
        ("N (°/√h)", &c.arw_deg_per_sqrt_h),
        ("B (°/h)", &c.bias_instability_deg_per_h),
        ("K (°/h/√h)", &c.rrw_deg_per_h_per_sqrt_h),
    ];
    let panels = bottom.split_evenly((1, 3));
    for ((name, values), panel) in series.iter().zip(panels.iter()) {
        let finite: Vec<(f64, f64)> = d
            .time_s
            .iter()
            .copied()
            .zip(values.iter().copied())
            .filter(|(_, v)| v.is_finite())
            .collect();
        let max = finite.iter().map(|p| p.1).fold(0.0f64, f64::max).max(1e-12);
        let mut chart = ChartBuilder::on(panel)
            .caption(*name, ("sans-serif", 16))
            .margin(8)
            .x_label_area_size(30)
            .y_label_area_size(60)
            .build_cartesian_2d(t0..t1, 0.0..max * 1.1)
            .map_err(|x| e(&x))?;
        chart
            .configure_mesh()
            .x_desc("time (s)")
            .y_label_formatter(&|v| format!("{v:.2e}"))
            .draw()
            .map_err(|x| e(&x))?;
        chart
            .draw_series(LineSeries::new(finite, COLORS[0].stroke_width(1)))
            .map_err(|x| e(&x))?;
    }
    area.present().map_err(|x| e(&x))
}

/// One gyro's trace across a switch, for [`gyro_loop`].
pub struct LoopTrace<'a> {
    /// Legend label (`gyro a`).
    pub label: String,
    /// The points.
    pub points: &'a [TracePoint],
}

/// The first time after the switch (s) from which the trace stays locked, if it does.
pub fn relock_time_s(points: &[TracePoint]) -> Option<f64> {
    let after: Vec<&TracePoint> = points.iter().filter(|p| p.time_s > 0.0).collect();
    let last_unlocked = after.iter().rposition(|p| !p.locked);
    match last_unlocked {
        Some(i) if i + 1 < after.len() => Some(after[i + 1].time_s),
        Some(_) => None,
        None => after.first().map(|p| p.time_s),
    }
}

fn draw_gyro_loop<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    traces: &[LoopTrace],
) -> std::result::Result<(), String> {
    let e = |x: &dyn std::fmt::Display| x.to_string();
    area.fill(&WHITE).map_err(|x| e(&x))?;
    let (title, body) = area.split_vertically(40);
    title
        .titled(
            "Mode switch at t = 0 (normal → reverse): drive amplitude, NCO frequency, rate",
            ("sans-serif", 20),
        )
        .map_err(|x| e(&x))?;
    let panels = body.split_evenly((3, 1));
    let all = || traces.iter().flat_map(|t| t.points.iter());
    let t0 = all().map(|p| p.time_s).fold(f64::MAX, f64::min);
    let t1 = all()
        .map(|p| p.time_s)
        .fold(f64::MIN, f64::max)
        .max(t0 + 1e-3);
    type Value = fn(&TracePoint) -> Option<f64>;
    let quantities: [(&str, Value); 3] = [
        ("drive amplitude (µm)", |p| Some(p.drive_amplitude_m * 1e6)),
        ("NCO frequency (Hz)", |p| Some(p.frequency_hz)),
        ("rate output (°/s)", |p| p.rate_dps),
    ];
    for ((name, value), panel) in quantities.iter().zip(panels.iter()) {
        let values: Vec<f64> = all().filter_map(value).filter(|v| v.is_finite()).collect();
        let lo = values.iter().copied().fold(f64::MAX, f64::min);
        let hi = values.iter().copied().fold(f64::MIN, f64::max);
        if values.is_empty() {
            continue;
        }
        let pad = ((hi - lo) * 0.05).max(1e-9);
        let (lo, hi) = (lo - pad, hi + pad);
        let mut chart = ChartBuilder::on(panel)
            .margin(8)
            .x_label_area_size(34)
            .y_label_area_size(80)
            .build_cartesian_2d(t0 * 1e3..t1 * 1e3, lo..hi)
            .map_err(|x| e(&x))?;
        chart
            .configure_mesh()
            .x_desc("time from the switch (ms)")
            .y_desc(*name)
            .draw()
            .map_err(|x| e(&x))?;
        chart
            .draw_series(std::iter::once(PathElement::new(
                vec![(0.0, lo), (0.0, hi)],
                BLACK.stroke_width(1),
            )))
            .map_err(|x| e(&x))?;
        for (i, trace) in traces.iter().enumerate() {
            let color = COLORS[i % COLORS.len()];
            let points: Vec<(f64, f64)> = trace
                .points
                .iter()
                .filter_map(|p| value(p).map(|v| (p.time_s * 1e3, v)))
                .filter(|(_, v)| v.is_finite())
                .collect();
            let label = match relock_time_s(trace.points) {
                Some(t) => format!("{} (locked again at {:.1} ms)", trace.label, t * 1e3),
                None => format!("{} (not locked again)", trace.label),
            };
            chart
                .draw_series(LineSeries::new(points, color.stroke_width(2)))
                .map_err(|x| e(&x))?
                .label(label)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], color));
            if let Some(t) = relock_time_s(trace.points) {
                chart
                    .draw_series(std::iter::once(PathElement::new(
                        vec![(t * 1e3, lo), (t * 1e3, hi)],
                        color.mix(0.5).stroke_width(1),
                    )))
                    .map_err(|x| e(&x))?;
            }
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .label_font(("sans-serif", 14))
            .draw()
            .map_err(|x| e(&x))?;
    }
    area.present().map_err(|x| e(&x))
}

/// Checks that `path` names a plot gyrofx can write (`.png` or `.svg`), before any work.
///
/// # Errors
/// [`Error::Plot`]-style error naming the path.
pub fn check_path(path: &Path) -> Result<()> {
    is_svg(path).map(|_| ())
}

/// Writes the gyro loop's switch traces (amplitude, NCO frequency, rate against time; the
/// switch and each gyro's re-lock marked) to `path` (PNG or SVG).
///
/// # Errors
/// A bad extension, no font, an empty trace, or a failure to draw or write.
pub fn gyro_loop(path: &Path, traces: &[LoopTrace]) -> Result<()> {
    let svg = is_svg(path)?;
    ensure_font()?;
    if traces.iter().all(|t| t.points.is_empty()) {
        return Err(plot_error(path, "no trace to plot"));
    }
    let size = (1100, 1000);
    atomically(path, |staged| {
        if svg {
            draw_gyro_loop(&SVGBackend::new(staged, size).into_drawing_area(), traces)
        } else {
            draw_gyro_loop(
                &BitMapBackend::new(staged, size).into_drawing_area(),
                traces,
            )
        }
    })
}

/// Draws into a temporary file beside `path` (same extension) and renames it into place only
/// when drawing succeeded: a failed plot leaves nothing behind.
fn atomically(
    path: &Path,
    draw: impl FnOnce(&Path) -> std::result::Result<(), String>,
) -> Result<()> {
    let folder = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let extension = path.extension().and_then(|x| x.to_str()).unwrap_or("png");
    let staged = gyrofx_codegen::output_folder::staged_file(
        folder,
        ".gyrofx-plot-",
        &format!(".{extension}"),
    )
    .map_err(|e| {
        plot_error(
            path,
            format!("cannot create a file in {}: {e}", folder.display()),
        )
    })?;
    draw(staged.path()).map_err(|e| plot_error(path, e))?;
    staged
        .persist(path)
        .map_err(|e| plot_error(path, format!("cannot move into place: {e}")))?;
    Ok(())
}

fn is_svg(path: &Path) -> Result<bool> {
    match path
        .extension()
        .and_then(|x| x.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("svg") => Ok(true),
        Some("png") => Ok(false),
        _ => Err(plot_error(path, "the file must end in .png or .svg")),
    }
}

/// Writes the Allan plot of `series` to `path` (PNG or SVG).
///
/// # Errors
/// A bad extension, no font, or a failure to draw or write.
pub fn allan(path: &Path, series: &[AllanSeries]) -> Result<()> {
    deviation(path, series, "Allan deviation")
}

/// Writes the plot of `series` to `path` (PNG or SVG) titled `title` (the deviation's kind:
/// "Modified Allan deviation", "Hadamard deviation", ...).
///
/// # Errors
/// A bad extension, no font, or a failure to draw or write.
pub fn deviation(path: &Path, series: &[AllanSeries], title: &str) -> Result<()> {
    let svg = is_svg(path)?;
    ensure_font()?;
    let size = (1000, 700);
    atomically(path, |staged| {
        if svg {
            draw_allan(
                &SVGBackend::new(staged, size).into_drawing_area(),
                series,
                title,
            )
        } else {
            draw_allan(
                &BitMapBackend::new(staged, size).into_drawing_area(),
                series,
                title,
            )
        }
    })
}

/// Writes the DAVAR heatmap and the coefficients over time to `path` (PNG or SVG).
///
/// # Errors
/// A bad extension, no font, or a failure to draw or write.
pub fn davar(path: &Path, d: &Davar, c: &Coefficients) -> Result<()> {
    let svg = is_svg(path)?;
    ensure_font()?;
    if d.time_s.is_empty() {
        return Err(plot_error(path, "no windows to plot"));
    }
    let size = (1200, 900);
    atomically(path, |staged| {
        if svg {
            draw_davar(&SVGBackend::new(staged, size).into_drawing_area(), d, c)
        } else {
            draw_davar(&BitMapBackend::new(staged, size).into_drawing_area(), d, c)
        }
    })
}
