//! `pareto.png` / `pareto.svg`: the target's metric against Xilinx LUTs (left) and DSP48E1s
//! (right), one point per measured candidate, each panel's Pareto front (no other candidate is
//! both cheaper and better) joined and ringed, the target's limit dashed, the chosen candidate
//! marked. Drawn with plotters, as [`crate::plot`] draws, and with the same font lookup.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use gyrofx_job::error::{Error, Result};

use super::target::Target;

/// One measured candidate on the plot.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    /// Its index in the sweep.
    pub index: usize,
    /// Xilinx LUTs.
    pub luts: f64,
    /// DSP48E1s.
    pub dsp48: f64,
    /// The target's metric.
    pub value: f64,
    /// Whether it meets the target (and overflowed nowhere).
    pub eligible: bool,
}

/// Indices (into `points`) of the Pareto front of `(cost, value)`, both minimized, in order of
/// rising cost: a point is on it when no other is at most as costly and at most as bad and
/// better in one (equal points are all on it).
pub fn front(points: &[(f64, f64)]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.sort_by(|&a, &b| {
        points[a]
            .0
            .total_cmp(&points[b].0)
            .then(points[a].1.total_cmp(&points[b].1))
    });
    let mut out: Vec<usize> = Vec::new();
    let mut best = f64::INFINITY;
    for i in order {
        let (cost, value) = points[i];
        let ties_last = out
            .last()
            .is_some_and(|&j| points[j].0 == cost && points[j].1 == value);
        if value < best || ties_last {
            best = best.min(value);
            out.push(i);
        }
    }
    out
}

const BLUE: RGBColor = RGBColor(31, 119, 180);
const GREY: RGBColor = RGBColor(150, 150, 150);
const RED: RGBColor = RGBColor(214, 39, 40);
const GREEN: RGBColor = RGBColor(44, 160, 44);

fn panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    points: &[Point],
    cost: impl Fn(&Point) -> f64,
    cost_label: &str,
    chosen: Option<usize>,
    target: &Target,
) -> std::result::Result<(), String> {
    let e = |x: &dyn std::fmt::Display| x.to_string();
    let costs: Vec<f64> = points.iter().map(&cost).collect();
    let values: Vec<f64> = points.iter().map(|p| p.value).collect();
    let (cmin, cmax) = costs
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), c| (a.min(*c), b.max(*c)));
    // Costs are counts: whole numbers at both ends, and only whole numbers labelled.
    let pad = ((cmax - cmin) * 0.08).max(1.0);
    let (x0, x1) = ((cmin - pad).floor(), (cmax + pad).ceil());
    let x_labels = ((x1 - x0) as usize + 1).clamp(2, 10);
    let positive: Vec<f64> = values
        .iter()
        .copied()
        .chain([target.limit])
        .filter(|v| *v > 0.0 && v.is_finite())
        .collect();
    let (vmin, vmax) = positive
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(*v), b.max(*v)));
    let (vmin, vmax) = if positive.is_empty() {
        (1e-12, 1.0)
    } else if vmin >= vmax {
        (vmin / 10.0, vmax * 10.0)
    } else {
        (vmin / 2.0, vmax * 2.0)
    };
    let mut chart = ChartBuilder::on(area)
        .margin(14)
        .x_label_area_size(48)
        .y_label_area_size(80)
        .build_cartesian_2d(x0..x1, (vmin..vmax).log_scale())
        .map_err(|x| e(&x))?;
    chart
        .configure_mesh()
        .x_desc(cost_label)
        .y_desc(target.metric.label())
        .x_labels(x_labels)
        .x_label_formatter(&|v| {
            if (v - v.round()).abs() < 1e-6 {
                format!("{v:.0}")
            } else {
                String::new()
            }
        })
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .draw()
        .map_err(|x| e(&x))?;
    // The limit: what meets the target lies below it.
    if target.limit > 0.0 {
        let steps = 40;
        chart
            .draw_series((0..steps).step_by(2).map(|i| {
                let at = |j: usize| x0 + (x1 - x0) * j as f64 / steps as f64;
                PathElement::new(
                    vec![(at(i), target.limit), (at(i + 1), target.limit)],
                    GREEN.stroke_width(1),
                )
            }))
            .map_err(|x| e(&x))?
            .label(format!("target {target}"))
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], GREEN.stroke_width(1)));
    }
    let shown = |v: f64| v > 0.0 && v.is_finite();
    chart
        .draw_series(
            points
                .iter()
                .zip(&costs)
                .filter(|(p, _)| shown(p.value))
                .map(|(p, c)| {
                    let color = if p.eligible { BLUE } else { GREY };
                    Circle::new((*c, p.value), 4, color.filled())
                }),
        )
        .map_err(|x| e(&x))?
        .label("candidate (grey: misses the target or overflows)")
        .legend(|(x, y)| Circle::new((x + 10, y), 4, BLUE.filled()));
    let pairs: Vec<(f64, f64)> = costs.iter().copied().zip(values.iter().copied()).collect();
    let on_front: Vec<usize> = front(&pairs)
        .into_iter()
        .filter(|&i| shown(values[i]))
        .collect();
    chart
        .draw_series(LineSeries::new(
            on_front.iter().map(|&i| (costs[i], values[i])),
            RED.stroke_width(1),
        ))
        .map_err(|x| e(&x))?
        .label("Pareto front")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED.stroke_width(1)));
    chart
        .draw_series(
            on_front
                .iter()
                .map(|&i| Circle::new((costs[i], values[i]), 7, RED.stroke_width(1))),
        )
        .map_err(|x| e(&x))?;
    if let Some(i) = chosen.and_then(|c| points.iter().position(|p| p.index == c)) {
        if shown(values[i]) {
            chart
                .draw_series([Circle::new(
                    (costs[i], values[i]),
                    11,
                    GREEN.stroke_width(2),
                )])
                .map_err(|x| e(&x))?;
            chart
                .draw_series([Cross::new((costs[i], values[i]), 9, GREEN.stroke_width(2))])
                .map_err(|x| e(&x))?
                .label(format!("chosen: candidate {}", points[i].index))
                .legend(|(x, y)| Cross::new((x + 10, y), 6, GREEN.stroke_width(2)));
        }
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 13))
        .draw()
        .map_err(|x| e(&x))?;
    Ok(())
}

fn draw<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    points: &[Point],
    chosen: Option<usize>,
    target: &Target,
    title: &str,
) -> std::result::Result<(), String> {
    let e = |x: &dyn std::fmt::Display| x.to_string();
    area.fill(&WHITE).map_err(|x| e(&x))?;
    let area = area.titled(title, ("sans-serif", 20)).map_err(|x| e(&x))?;
    let [left, right]: [DrawingArea<DB, Shift>; 2] = area
        .split_evenly((1, 2))
        .try_into()
        .map_err(|_| "two panels".to_string())?;
    panel(
        &left,
        points,
        |p| p.luts,
        "Xilinx 7-series LUTs",
        chosen,
        target,
    )?;
    panel(&right, points, |p| p.dsp48, "DSP48E1", chosen, target)?;
    area.present().map_err(|x| e(&x))
}

/// The plot as PNG bytes and SVG text.
///
/// # Errors
/// No font, nothing to plot, or a failure to draw.
pub fn render(
    points: &[Point],
    chosen: Option<usize>,
    target: &Target,
    title: &str,
) -> Result<(Vec<u8>, String)> {
    crate::plot::ensure_font()?;
    if points.is_empty() {
        return Err(Error::Plot(
            "pareto: no candidate was measured, nothing to plot".into(),
        ));
    }
    let size = (1400, 650);
    let fail = |what: &str, message: String| Error::Plot(format!("pareto.{what}: {message}"));
    let mut svg = String::new();
    draw(
        &SVGBackend::with_string(&mut svg, size).into_drawing_area(),
        points,
        chosen,
        target,
        title,
    )
    .map_err(|m| fail("svg", m))?;
    // plotters encodes PNG only into a file.
    let scratch = tempfile::tempdir().map_err(|e| Error::io(std::env::temp_dir(), e))?;
    let png_path: &Path = &scratch.path().join("pareto.png");
    draw(
        &BitMapBackend::new(png_path, size).into_drawing_area(),
        points,
        chosen,
        target,
        title,
    )
    .map_err(|m| fail("png", m))?;
    let png = std::fs::read(png_path).map_err(|e| Error::io(png_path, e))?;
    Ok((png, svg))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against a brute-force check of the definition.
    #[test]
    fn the_front_holds_exactly_the_undominated_points() {
        let points = [
            (10.0, 5.0),
            (12.0, 3.0),
            (12.0, 4.0),
            (15.0, 3.0),
            (20.0, 1.0),
            (8.0, 9.0),
            (20.0, 1.0),
        ];
        let dominated = |i: usize| {
            points.iter().enumerate().any(|(j, q)| {
                j != i
                    && q.0 <= points[i].0
                    && q.1 <= points[i].1
                    && (q.0 < points[i].0 || q.1 < points[i].1)
            })
        };
        let mut expected: Vec<usize> = (0..points.len()).filter(|&i| !dominated(i)).collect();
        let mut got = front(&points);
        got.sort_unstable();
        expected.sort_unstable();
        assert_eq!(got, expected);
    }
}
