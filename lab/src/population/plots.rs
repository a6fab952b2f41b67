//! The population's plots, SVG (text, the same bytes on every run): a histogram of each
//! figure that some member has (`hist_<figure>.svg`) and the yield against the sequencer's
//! blanking (`yield_vs_blanking.svg`).

use plotters::coord::Shift;
use plotters::prelude::*;

use gyrofx_job::error::{Error, Result};
use gyrofx_job::population::summary::{Report, Summary};
use gyrofx_job::population::targets::Figure;

const BLUE: RGBColor = RGBColor(31, 119, 180);

/// Bins of a histogram.
const BINS: usize = 30;

/// `(file name, SVG)` of every plot.
///
/// # Errors
/// No font, or a failure to draw.
pub fn render(summary: &Summary, report: &Report) -> Result<Vec<(String, String)>> {
    crate::plot::ensure_font()?;
    let size = (800, 500);
    let mut out = Vec::new();
    for figure in Figure::ALL {
        let values = summary.values(figure);
        if values.is_empty() {
            continue;
        }
        let name = format!("hist_{}.svg", figure.name());
        let mut svg = String::new();
        histogram(
            &SVGBackend::with_string(&mut svg, size).into_drawing_area(),
            values,
            figure.name(),
            report.counts.members,
        )
        .map_err(|m| Error::Plot(format!("{name}: {m}")))?;
        out.push((name, svg));
    }
    let mut svg = String::new();
    yield_curve(
        &SVGBackend::with_string(&mut svg, size).into_drawing_area(),
        report,
    )
    .map_err(|m| Error::Plot(format!("yield_vs_blanking.svg: {m}")))?;
    out.push(("yield_vs_blanking.svg".into(), svg));
    Ok(out)
}

fn histogram<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    values: &[f64],
    name: &str,
    members: u64,
) -> std::result::Result<(), String> {
    let e = |x: &dyn std::fmt::Display| x.to_string();
    area.fill(&WHITE).map_err(|x| e(&x))?;
    let (lo, hi) = values
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(*v), b.max(*v)));
    let width = if hi > lo {
        (hi - lo) / BINS as f64
    } else {
        1.0
    };
    let mut counts = [0u64; BINS];
    for v in values {
        let bin = (((v - lo) / width) as usize).min(BINS - 1);
        counts[bin] += 1;
    }
    let top = counts.iter().copied().max().unwrap_or(1).max(1);
    let mut chart = ChartBuilder::on(area)
        .caption(
            format!("{name}: {} of {members} members", values.len()),
            ("sans-serif", 20),
        )
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(50)
        .build_cartesian_2d(lo..lo + width * BINS as f64, 0u64..top + top / 10 + 1)
        .map_err(|x| e(&x))?;
    chart
        .configure_mesh()
        .x_desc(name)
        .y_desc("members")
        .draw()
        .map_err(|x| e(&x))?;
    chart
        .draw_series(counts.iter().enumerate().map(|(i, c)| {
            let x0 = lo + width * i as f64;
            Rectangle::new([(x0, 0), (x0 + width, *c)], BLUE.filled())
        }))
        .map_err(|x| e(&x))?;
    area.present().map_err(|x| e(&x))
}

fn yield_curve<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    report: &Report,
) -> std::result::Result<(), String> {
    let e = |x: &dyn std::fmt::Display| x.to_string();
    area.fill(&WHITE).map_err(|x| e(&x))?;
    let last = report
        .yield_against_blanking
        .last()
        .map_or(1.0, |b| b.blank_ms.max(1.0));
    let mut chart = ChartBuilder::on(area)
        .caption(
            "yield (every target met, settled within the blanking)",
            ("sans-serif", 20),
        )
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(50)
        .build_cartesian_2d(0.0..last, 0.0..1.05)
        .map_err(|x| e(&x))?;
    chart
        .configure_mesh()
        .x_desc("blanking after a switch, ms")
        .y_desc("yield")
        .draw()
        .map_err(|x| e(&x))?;
    chart
        .draw_series(LineSeries::new(
            report
                .yield_against_blanking
                .iter()
                .map(|b| (b.blank_ms, b.yield_fraction)),
            BLUE.stroke_width(2),
        ))
        .map_err(|x| e(&x))?;
    area.present().map_err(|x| e(&x))
}
