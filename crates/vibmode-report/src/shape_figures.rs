//! Figures of the multichannel modes: each structural mode's shape on the sensor layout seen
//! from above, and the MAC matrix between the physical model's modes and the identified ones.

use vibmode_core::{Corner, InvariantMode, ModeClass, ReferenceMode, Role};

use crate::model::{Figure, Marker, Panel, Rgb, Series, SeriesStyle};
use crate::panels::grid;

/// Where a sensor is drawn in the plan view (schematic units: the body spans -1..1 along the
/// vehicle, front to the right, and -0.6..0.6 across it, left up). Unsprung sensors sit on the
/// wheels outside the body outline, sprung ones on the body above them. `None`: no corner.
pub fn layout_position(role: Role, corner: Option<Corner>) -> Option<(f64, f64)> {
    let (x, y) = match corner? {
        Corner::FL => (1.0, 1.0),
        Corner::FR => (1.0, -1.0),
        Corner::RL => (-1.0, 1.0),
        Corner::RR => (-1.0, -1.0),
    };
    Some(match role {
        Role::Unsprung => (0.75 * x, 0.8 * y),
        _ => (0.75 * x, 0.45 * y),
    })
}

/// Colour of a shape entry in phase (within 90 degrees) with the shape's largest entry.
const IN_PHASE: Rgb = Rgb::BLUE;
/// Colour of an entry in opposite phase.
const OPPOSITE: Rgb = Rgb::RED;

fn outline() -> Vec<Series> {
    let body = Series::line(
        vec![-1.0, 1.0, 1.0, -1.0, -1.0],
        vec![-0.6, -0.6, 0.6, 0.6, -0.6],
    )
    .with_color(Rgb::GREY)
    .with_style(SeriesStyle::Line {
        width: 1,
        dashed: false,
    });
    // The front: an arrow head on the right edge.
    let front = Series::line(vec![1.0, 1.12, 1.0], vec![-0.15, 0.0, 0.15])
        .with_color(Rgb::GREY)
        .with_style(SeriesStyle::Line {
            width: 1,
            dashed: false,
        });
    vec![body, front]
}

/// One panel: the shape `shape` (one `[re, im]` per channel) of the mode titled `title`, with a
/// circle per sensor of `positions` (None: not drawn) whose area grows with the entry's modulus
/// (relative to the largest), blue in phase with the largest entry and red opposite.
pub fn shape_panel(title: &str, shape: &[[f64; 2]], positions: &[Option<(f64, f64)>]) -> Panel {
    let mut panel = Panel::new(title, "rear  <-  x  ->  front", "right  <-  y  ->  left")
        .with_x_range(-1.3, 1.3)
        .with_y_range(-1.15, 1.15)
        .without_legend();
    panel.series.extend(outline());
    let largest = shape
        .iter()
        .copied()
        .max_by(|a, b| a[0].hypot(a[1]).total_cmp(&b[0].hypot(b[1])))
        .unwrap_or([1.0, 0.0]);
    let max_mod = largest[0].hypot(largest[1]);
    let (mut in_labelled, mut opp_labelled) = (false, false);
    for (v, pos) in shape.iter().zip(positions) {
        let Some((x, y)) = *pos else { continue };
        let modulus = if max_mod > 0.0 {
            v[0].hypot(v[1]) / max_mod
        } else {
            0.0
        };
        // Sign of the projection on the largest entry: Re(v conj(largest)).
        let in_phase = v[0] * largest[0] + v[1] * largest[1] >= 0.0;
        let size = (3.0 + 17.0 * modulus.sqrt()).round() as u32;
        let mut s = Series::points(vec![x], vec![y], Marker::Circle)
            .with_color(if in_phase { IN_PHASE } else { OPPOSITE })
            .with_alpha(0.8)
            .with_style(SeriesStyle::Points {
                size,
                marker: Marker::Circle,
            });
        if in_phase && !in_labelled {
            s = s.with_label("in phase with the largest");
            in_labelled = true;
        } else if !in_phase && !opp_labelled {
            s = s.with_label("opposite phase");
            opp_labelled = true;
        }
        panel.series.push(s);
    }
    panel
}

/// The structural modes with shapes, in frequency order (as the shape table lists them).
pub fn shaped_structural(modes: &[InvariantMode]) -> Vec<&InvariantMode> {
    modes
        .iter()
        .filter(|m| m.class == ModeClass::Structural && m.shape.is_some())
        .collect()
}

/// The mode-shape figure: one plan-view panel per structural mode with a shape (`labels[k]`
/// appended to its title, e.g. the matched model mode). `None` when no channel has a corner or
/// no mode has a shape.
pub fn mode_shapes_figure(
    modes: &[&InvariantMode],
    labels: &[Option<String>],
    positions: &[Option<(f64, f64)>],
) -> Option<Figure> {
    if modes.is_empty() || positions.iter().all(Option::is_none) {
        return None;
    }
    let panels = modes
        .iter()
        .enumerate()
        .filter_map(|(k, m)| {
            let shape = m.shape.as_ref()?;
            let mut title = format!(
                "{}: {:.3} Hz, damping {:.3}",
                k + 1,
                m.frequency_hz,
                m.damping_ratio
            );
            if let Some(Some(l)) = labels.get(k) {
                title.push_str(&format!(" ({l})"));
            }
            Some(shape_panel(&title, shape, positions))
        })
        .collect();
    Some(grid(panels, 3, 420, 340))
}

/// MAC bins of the matrix figure: lower bound, colour and legend text, best first.
const MAC_BINS: [(f64, Rgb, &str); 5] = [
    (0.9, Rgb::new(0x00, 0x44, 0x1b), "MAC >= 0.9"),
    (0.7, Rgb::new(0x2c, 0xa0, 0x2c), "0.7-0.9"),
    (0.5, Rgb::new(0x98, 0xdf, 0x8a), "0.5-0.7"),
    (0.2, Rgb::new(0xd9, 0xd9, 0xd9), "0.2-0.5"),
    (f64::NEG_INFINITY, Rgb::new(0xf7, 0xf7, 0xf7), "< 0.2"),
];

/// The MAC matrix as a figure: one square per (identified mode `j`, model mode `i`) at
/// `(j + 1, i + 1)` (the first row at the bottom, so that the ticks are the row numbers), coloured by its MAC in five bins. `mac[i][j]`: model mode `i` against
/// identified mode `j`. `None` for an empty matrix.
pub fn mac_matrix_figure(mac: &[Vec<f64>]) -> Option<Figure> {
    let n_model = mac.len();
    let n_ident = mac.first().map_or(0, Vec::len);
    if n_model == 0 || n_ident == 0 {
        return None;
    }
    let mut panel = Panel::new(
        "MAC, model modes x identified modes",
        "identified mode (MAC table column)",
        "model mode (MAC table row)",
    )
    // Room on the right for the legend.
    .with_x_range(0.4, n_ident as f64 + 0.6 + 0.35 * n_ident as f64)
    .with_y_range(0.4, n_model as f64 + 0.6);
    // Half the side of a square, px: the plot area is about 600 x 440 px.
    let cell = (0.42 * (420.0 / n_ident as f64).min(440.0 / n_model as f64)).clamp(2.0, 30.0);
    let cell = cell.round() as u32;
    for (lo, color, label) in MAC_BINS {
        let hi = MAC_BINS
            .iter()
            .filter(|b| b.0 > lo)
            .map(|b| b.0)
            .fold(f64::INFINITY, f64::min);
        let (mut x, mut y) = (Vec::new(), Vec::new());
        for (i, row) in mac.iter().enumerate() {
            for (j, &v) in row.iter().enumerate() {
                if v >= lo && v < hi {
                    x.push(j as f64 + 1.0);
                    y.push(i as f64 + 1.0);
                }
            }
        }
        panel.series.push(
            Series::points(x, y, Marker::Square)
                .with_color(color)
                .with_style(SeriesStyle::Points {
                    size: cell,
                    marker: Marker::Square,
                }),
        );
        // The legend entry: no data, a small marker.
        panel.series.push(
            Series::points(Vec::new(), Vec::new(), Marker::Square)
                .with_color(color)
                .with_label(label)
                .with_style(SeriesStyle::Points {
                    size: 5,
                    marker: Marker::Square,
                }),
        );
    }
    Some(grid(vec![panel], 1, 700, 560))
}

/// MAC of every model mode with a shape at `channels` (rows) against every mode of `modes`
/// (columns); the rows' labels with their frequencies.
pub fn mac_matrix(
    reference: &[ReferenceMode],
    channels: &[String],
    modes: &[&InvariantMode],
) -> (Vec<String>, Vec<Vec<f64>>) {
    reference
        .iter()
        .filter_map(|r| r.shape_for(channels).map(|s| (r, s)))
        .map(|(r, rs)| {
            let row = modes
                .iter()
                .map(|m| {
                    m.shape
                        .as_ref()
                        .map_or(0.0, |ms| vibmode_modal::shapes::mac(&rs, ms))
                })
                .collect();
            (format!("{} {:.3} Hz", r.label, r.frequency_hz), row)
        })
        .unzip()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn corners_are_placed_front_right_left_up() {
        let fl = layout_position(Role::Unsprung, Some(Corner::FL)).unwrap();
        let rr = layout_position(Role::Sprung, Some(Corner::RR)).unwrap();
        assert!(fl.0 > 0.0 && fl.1 > 0.0);
        assert!(rr.0 < 0.0 && rr.1 < 0.0);
        // Wheels outside the body outline (|y| 0.6), body sensors inside.
        assert!(fl.1 > 0.6 && rr.1.abs() < 0.6);
        assert_eq!(layout_position(Role::Other, None), None);
    }

    #[test]
    fn opposite_entries_are_red_and_sizes_follow_the_modulus() {
        let shape = [[1.0, 0.0], [-0.25, 0.0], [0.0, 0.0]];
        let pos = [Some((1.0, 0.5)), Some((-1.0, 0.5)), None];
        let p = shape_panel("t", &shape, &pos);
        let points: Vec<&Series> = p
            .series
            .iter()
            .filter(|s| matches!(s.style, SeriesStyle::Points { .. }))
            .collect();
        assert_eq!(
            points.len(),
            2,
            "the sensor without a position is not drawn"
        );
        assert_eq!(points[0].color, Some(IN_PHASE));
        assert_eq!(points[1].color, Some(OPPOSITE));
        let size = |s: &Series| match s.style {
            SeriesStyle::Points { size, .. } => size,
            _ => 0,
        };
        // sqrt scaling of the radius: area proportional to the modulus.
        assert_eq!(size(points[0]), 20);
        assert_eq!(size(points[1]), 12);
    }

    #[test]
    fn every_cell_of_the_mac_matrix_is_drawn_once_in_its_bin() {
        let mac = vec![vec![0.95, 0.1, 0.55], vec![0.3, 0.75, 0.2]];
        let f = mac_matrix_figure(&mac).unwrap();
        let p = &f.panels[0];
        let n: usize = p.series.iter().map(|s| s.x.len()).sum();
        assert_eq!(n, 6);
        // Each bin: the cells, then its legend entry (no data).
        let bin = |label: &str| {
            let k = p
                .series
                .iter()
                .position(|s| s.label.as_deref() == Some(label))?;
            assert!(p.series[k].x.is_empty());
            p.series.get(k - 1)
        };
        assert_eq!(bin("MAC >= 0.9").unwrap().x, vec![1.0]);
        assert_eq!(bin("0.7-0.9").unwrap().y, vec![2.0]);
        assert_eq!(bin("MAC >= 0.9").unwrap().y, vec![1.0]);
        assert_eq!(bin("0.5-0.7").unwrap().x, vec![3.0]);
        assert_eq!(bin("0.2-0.5").unwrap().x, vec![1.0, 3.0]);
        assert_eq!(bin("< 0.2").unwrap().x, vec![2.0]);
        assert!(mac_matrix_figure(&[]).is_none());
    }
}
