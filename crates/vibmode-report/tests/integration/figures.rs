//! Rendering tests: SVG content, PNG files, text pixels from the embedded font, robustness on
//! awkward data, layout, and every error path.

use vibmode_report::plotters::prelude::{BitMapBackend, IntoDrawingArea};
use vibmode_report::{
    Figure, Marker, Panel, ReportError, Rgb, Scale, Series, SeriesStyle, MAX_POINTS_PER_SERIES,
};

fn psd_panel() -> Panel {
    let f: Vec<f64> = (0..=400).map(|i| i as f64 * 0.1).collect();
    let p: Vec<f64> = f.iter().map(|&f| 1.0 / (1.0 + (f - 9.0).powi(2))).collect();
    Panel::new("Welch PSD, FR", "Frequency [Hz]", "PSD [(m/s²)²/Hz]")
        .with_scales(Scale::Linear, Scale::Log)
        .with_series(Series::line(f, p).with_label("Welch"))
        .with_series(
            Series::vlines(vec![1.1, 9.0])
                .with_color(Rgb::RED)
                .with_label("modes"),
        )
}

/// Render into an RGB buffer with plotters' BitMapBackend::with_buffer.
fn render(fig: &Figure) -> Vec<u8> {
    let (w, h) = (fig.width_px, fig.height_px);
    let mut buf = vec![0u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        fig.draw_on(&root).expect("draws");
        root.present().expect("present");
    }
    buf
}

fn pixel(buf: &[u8], w: u32, x: u32, y: u32) -> (u8, u8, u8) {
    let i = ((y * w + x) * 3) as usize;
    (buf[i], buf[i + 1], buf[i + 2])
}

/// Pixels in rows [y0, y1) that are clearly darker than the white background.
fn dark_pixels(buf: &[u8], w: u32, y0: u32, y1: u32) -> usize {
    (y0..y1)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            let (r, g, b) = pixel(buf, w, x, y);
            u32::from(r) + u32::from(g) + u32::from(b) < 3 * 128
        })
        .count()
}

#[test]
fn title_text_is_rasterised_with_the_embedded_font() {
    let mut fig = Figure::single(psd_panel());
    fig.width_px = 600;
    fig.height_px = 400;
    fig.title = Some("Bus FR spindle ÄÖ 1.1 Hz".into());
    let with_title = render(&fig);
    // The title band is the top ~34 px of a 600x400 figure; nothing but the title is drawn there.
    let n = dark_pixels(&with_title, 600, 0, 26);
    assert!(
        n > 150,
        "only {n} dark pixels in the title band: title text missing"
    );
    // Control: same layout (band present) but a blank title → the band stays empty.
    fig.title = Some(" ".into());
    let blank = render(&fig);
    assert_eq!(dark_pixels(&blank, 600, 0, 26), 0);
    // render_rgb (the crate's own buffer renderer) gives the same image.
    fig.title = Some("Bus FR spindle ÄÖ 1.1 Hz".into());
    assert_eq!(fig.render_rgb().unwrap(), with_title);
}

#[test]
fn svg_contains_title_axis_labels_and_font_family() {
    let mut fig = Figure::single(psd_panel());
    fig.title = Some("Record <3> & more".into());
    let svg = fig.to_svg_string().unwrap();
    assert!(svg.starts_with("<svg"));
    assert!(svg.contains("Welch PSD, FR"));
    assert!(svg.contains("Frequency [Hz]"));
    assert!(svg.contains("PSD [(m/s²)²/Hz]"));
    assert!(
        svg.contains("Record &lt;3&gt; &amp; more"),
        "title escaped in SVG"
    );
    assert!(svg.contains("font-family=\"DejaVu Sans, Verdana, sans-serif\""));
    // Every text element uses the embedded family.
    let fams: Vec<&str> = svg
        .split("font-family=\"")
        .skip(1)
        .map(|r| r.split('"').next().unwrap())
        .collect();
    assert!(fams.len() > 8);
    assert!(
        fams.iter().all(|f| *f == vibmode_report::FONT_FAMILY),
        "{fams:?}"
    );
    // Legend labels and log tick labels.
    assert!(svg.contains(">\nWelch\n<") && svg.contains(">\nmodes\n<"));
    assert!(
        svg.contains(">\n0.01\n<") || svg.contains(">\n1e-3\n<"),
        "decade tick labels"
    );
}

#[test]
fn log_axes_with_zero_negative_nan_and_inf_do_not_panic() {
    let x = vec![-1.0, 0.0, 1.0, 2.0, f64::NAN, 3.0, f64::INFINITY, 4.0];
    let y = vec![1.0, -2.0, 0.0, 1e-300, 5.0, f64::NEG_INFINITY, 2.0, 1e300];
    for style in [
        SeriesStyle::default(),
        SeriesStyle::Points {
            size: 3,
            marker: Marker::Square,
        },
    ] {
        let panel = Panel::new("log-log", "f [Hz]", "P [-]")
            .with_scales(Scale::Log, Scale::Log)
            .with_series(Series::line(x.clone(), y.clone()).with_style(style))
            .with_series(Series::vlines(vec![-3.0, 0.0, 2.5, f64::NAN]));
        let fig = Figure::single(panel);
        let svg = fig.to_svg_string().unwrap();
        assert!(svg.contains("log-log"));
        assert!(
            !svg.contains("NaN") && !svg.contains("inf"),
            "no garbage coordinates"
        );
        fig.render_rgb().unwrap();
    }
    // Only invalid data on a log axis: renders "no data".
    let panel = Panel::new("nothing", "f [Hz]", "P [-]")
        .with_scales(Scale::Log, Scale::Log)
        .with_series(Series::line(vec![-1.0, 0.0], vec![0.0, -5.0]));
    let svg = Figure::single(panel).to_svg_string().unwrap();
    assert!(svg.contains("no data"));
}

#[test]
fn empty_panel_says_no_data_and_data_panel_does_not() {
    let svg = Figure::single(Panel::new("empty", "t [s]", "a [m/s²]"))
        .to_svg_string()
        .unwrap();
    assert!(svg.contains("no data"));
    let svg = Figure::single(psd_panel()).to_svg_string().unwrap();
    assert!(!svg.contains("no data"));
}

#[test]
fn nan_breaks_a_line_into_separate_polylines() {
    let colour = Rgb::new(0x12, 0x34, 0x56);
    let count = |y: Vec<f64>| {
        let x: Vec<f64> = (0..y.len()).map(|i| i as f64).collect();
        let panel =
            Panel::new("p", "x [-]", "y [-]").with_series(Series::line(x, y).with_color(colour));
        let svg = Figure::single(panel).to_svg_string().unwrap();
        svg.lines()
            .filter(|l| l.contains("<polyline") && l.contains("stroke=\"#123456\""))
            .count()
    };
    assert_eq!(count(vec![0.0, 1.0, 2.0, 3.0, 2.0, 1.0]), 1);
    assert_eq!(count(vec![0.0, 1.0, 2.0, f64::NAN, 2.0, 1.0]), 2);
    assert_eq!(
        count(vec![0.0, f64::NAN, 2.0, f64::NAN, 2.0, 1.0]),
        1,
        "lone points draw nothing"
    );
}

#[test]
fn vlines_span_the_whole_panel_height() {
    let panel = Panel::new("", "f [Hz]", "P [-]")
        .with_x_range(0.0, 10.0)
        .with_series(Series::line(vec![0.0, 10.0], vec![0.0, 1.0]).with_color(Rgb::BLUE))
        .with_series(
            Series::vlines(vec![5.0, 50.0])
                .with_style(SeriesStyle::VLines { dotted: false })
                .with_color(Rgb::new(255, 0, 0)),
        );
    let mut fig = Figure::single(panel);
    fig.width_px = 400;
    fig.height_px = 300;
    let buf = render(&fig);
    let red = |x: u32| {
        (0..300)
            .filter(|&y| pixel(&buf, 400, x, y) == (255, 0, 0))
            .count()
    };
    let (best_x, best) = (0..400).map(|x| (x, red(x))).max_by_key(|p| p.1).unwrap();
    assert!(best > 200, "vertical line only {best} px tall of 300");
    // 5 Hz is the middle of the x range, so the line sits in the middle of the plotting area.
    assert!((150..300).contains(&best_x), "at x = {best_x}");
    // The out-of-range line at 50 Hz is not drawn at all.
    let columns_with_red = (0..400).filter(|&x| red(x) > 0).count();
    assert!(columns_with_red <= 3, "{columns_with_red} columns with red");
}

#[test]
fn four_panels_in_two_columns() {
    let panels: Vec<Panel> = (1..=4)
        .map(|k| {
            Panel::new(format!("Panel{k}"), "t [s]", "a [m/s²]")
                .with_series(Series::line(vec![0.0, 1.0], vec![0.0, k as f64]))
        })
        .collect();
    let fig = Figure::grid(Some("Raw vs resampled"), panels, 2);
    assert_eq!(fig.grid_shape(), (2, 2));
    let (w, h) = (fig.width_px as f64, fig.height_px as f64);
    let svg = fig.to_svg_string().unwrap();
    // Position of each panel title: 1 and 3 left, 2 and 4 right; 1, 2 top and 3, 4 bottom.
    let pos = |title: &str| -> (f64, f64) {
        let end = svg.find(&format!("\n{title}\n")).expect("title present");
        let start = svg[..end].rfind("<text").unwrap();
        let tag = &svg[start..end];
        let attr = |name: &str| -> f64 {
            let i = tag.find(&format!(" {name}=\"")).unwrap() + name.len() + 3;
            tag[i..].split('"').next().unwrap().parse().unwrap()
        };
        (attr("x"), attr("y"))
    };
    let p: Vec<(f64, f64)> = (1..=4).map(|k| pos(&format!("Panel{k}"))).collect();
    assert!(p[0].0 < w / 2.0 && p[2].0 < w / 2.0 && p[1].0 > w / 2.0 && p[3].0 > w / 2.0);
    assert!(p[0].1 < h / 2.0 && p[1].1 < h / 2.0 && p[2].1 > h / 2.0 && p[3].1 > h / 2.0);
    // Columns larger than the panel count collapse to one row.
    let mut one_row = fig.clone();
    one_row.columns = 9;
    assert_eq!(one_row.grid_shape(), (1, 4));
}

#[test]
fn long_series_are_decimated_but_keep_their_peaks() {
    let n = 400_000;
    let x: Vec<f64> = (0..n).map(|i| i as f64 / 20_000.0).collect();
    let mut y: Vec<f64> = x.iter().map(|t| (t * 7.0).sin()).collect();
    y[123_457] = 25.0; // one-sample spike
    let colour = Rgb::new(0x65, 0x43, 0x21);
    let panel = Panel::new("20 kHz record", "Time [s]", "a [m/s²]")
        .with_series(Series::line(x, y).with_color(colour));
    let fig = Figure::single(panel);
    let svg = fig.to_svg_string().unwrap();
    let line = svg
        .lines()
        .find(|l| l.contains("stroke=\"#654321\""))
        .expect("series drawn");
    let n_pts = line.matches(',').count();
    assert!(n_pts <= MAX_POINTS_PER_SERIES, "{n_pts} points drawn");
    assert!(n_pts > 1000);
    assert!(svg.len() < 200_000, "SVG is {} bytes", svg.len());
    // The spike reaches the top of the plotting area: the smallest y pixel of the polyline is
    // within a few pixels of the top padding (5 % of the span above 25).
    let min_y = line
        .split("points=\"")
        .nth(1)
        .unwrap()
        .split_whitespace()
        .filter_map(|p| p.split(',').nth(1))
        .filter_map(|v| v.trim_end_matches('"').parse::<i32>().ok())
        .min()
        .unwrap();
    assert!(min_y < 60, "peak drawn at y = {min_y}");
}

#[test]
fn explicit_ranges_clip_data() {
    let panel = Panel::new("zoom", "f [Hz]", "P [-]")
        .with_x_range(2.0, 4.0)
        .with_y_range(0.0, 1.0)
        .with_series(
            Series::line(
                (0..100).map(f64::from).collect(),
                (0..100).map(|i| f64::from(i % 3)).collect(),
            )
            .with_color(Rgb::new(1, 2, 3)),
        );
    let svg = Figure::single(panel).to_svg_string().unwrap();
    assert!(svg.contains("stroke=\"#010203\""));
    // Tick labels come from the explicit range.
    assert!(svg.contains(">\n2\n<") && svg.contains(">\n4\n<") && !svg.contains(">\n10\n<"));
}

#[test]
fn png_file_is_written_with_signature_and_size() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("psd.png");
    let mut fig = Figure::single(psd_panel());
    fig.width_px = 640;
    fig.height_px = 480;
    fig.save(&path).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    assert_eq!(&bytes[12..16], b"IHDR");
    let w = u32::from_be_bytes(bytes[16..20].try_into().unwrap());
    let h = u32::from_be_bytes(bytes[20..24].try_into().unwrap());
    assert_eq!((w, h), (640, 480));
    assert!(bytes.len() > 5_000, "PNG suspiciously small");
    // And SVG by extension (upper case too).
    let svg_path = dir.path().join("psd.SVG");
    fig.save(&svg_path).unwrap();
    assert!(std::fs::read_to_string(&svg_path)
        .unwrap()
        .starts_with("<svg"));
}

#[test]
fn all_marker_shapes_render() {
    let mut panel = Panel::new("markers", "f [Hz]", "ζ [-]").with_scales(Scale::Linear, Scale::Log);
    for (k, m) in ["circle", "cross", "diamond", "square", "triangle"]
        .iter()
        .enumerate()
    {
        let marker: Marker = m.parse().unwrap();
        assert_eq!(marker.to_string(), *m);
        panel.series.push(
            Series::points(vec![k as f64 + 1.0], vec![0.01 * (k as f64 + 1.0)], marker)
                .with_label(*m)
                .with_alpha(0.7),
        );
    }
    let svg = Figure::single(panel.clone()).to_svg_string().unwrap();
    for m in ["circle", "cross", "diamond", "square", "triangle"] {
        assert!(svg.contains(&format!(">\n{m}\n<")), "legend entry {m}");
    }
    assert!(
        svg.contains("<polygon"),
        "diamond/triangle drawn as polygons"
    );
    let mut fig = Figure::single(panel);
    fig.width_px = 300;
    fig.height_px = 200;
    fig.render_rgb().unwrap();
}

#[test]
fn serde_round_trip() {
    let fig = Figure::grid(Some("t"), vec![psd_panel()], 1);
    let json = serde_json::to_string(&fig).unwrap();
    assert!(json.contains("\"log\"") && json.contains("\"vlines\""));
    let mut back: Figure = serde_json::from_str(&json).unwrap();
    // Data round-trip to the last digit or so (serde_json's default float parser); everything
    // else exactly.
    for (a, b) in back.panels[0].series.iter_mut().zip(&fig.panels[0].series) {
        assert_eq!(a.x.len(), b.x.len());
        assert_eq!(a.y.len(), b.y.len());
        for (u, v) in a.x.iter().chain(&a.y).zip(b.x.iter().chain(&b.y)) {
            assert!((u - v).abs() <= 1e-15 * v.abs(), "{u} vs {v}");
        }
        a.x.clone_from(&b.x);
        a.y.clone_from(&b.y);
    }
    assert_eq!(back, fig);
}

// ---------- error paths ----------

fn err_text(r: Result<String, ReportError>) -> String {
    let s = match r {
        Ok(_) => panic!("must fail"),
        Err(e) => e.to_string(),
    };
    assert!(!s.contains('\n'), "one-line message: {s}");
    s
}

#[test]
fn bad_figures_give_helpful_errors() {
    let ok = Figure::single(psd_panel());

    let mut f = ok.clone();
    f.width_px = 50;
    let s = err_text(f.to_svg_string());
    assert!(
        s.contains("50x600") && s.contains("between 100 and 16384"),
        "{s}"
    );

    let mut f = ok.clone();
    f.columns = 0;
    assert!(err_text(f.to_svg_string()).contains("columns (0)"));

    let mut f = ok.clone();
    f.panels.clear();
    assert!(err_text(f.to_svg_string()).contains("no panels"));

    let mut f = ok.clone();
    f.panels = vec![psd_panel(); 30];
    f.columns = 5;
    let s = err_text(f.to_svg_string());
    assert!(
        s.contains("6 rows x 5 columns") && s.contains("larger figure"),
        "{s}"
    );

    let mut f = ok.clone();
    f.panels[0]
        .series
        .push(Series::line(vec![1.0, 2.0], vec![1.0]).with_label("bad"));
    let s = err_text(f.to_svg_string());
    assert!(
        s.contains("'bad'") && s.contains("x has 2 values but y has 1"),
        "{s}"
    );

    let mut f = ok.clone();
    f.panels[0].series[0].alpha = 1.5;
    assert!(err_text(f.to_svg_string()).contains("alpha (1.5)"));
    f.panels[0].series[0].alpha = f64::NAN;
    assert!(err_text(f.to_svg_string()).contains("alpha (NaN)"));

    let mut f = ok.clone();
    f.panels[0].series[0].style = SeriesStyle::Line {
        width: 0,
        dashed: false,
    };
    assert!(err_text(f.to_svg_string()).contains("width (0)"));

    let mut f = ok.clone();
    f.panels[0].y_range = Some((0.0, 1.0)); // y is log
    let s = err_text(f.to_svg_string());
    assert!(s.contains("y range (0, 1)") && s.contains("lo > 0"), "{s}");

    let mut f = ok.clone();
    f.panels[0].x_range = Some((5.0, 5.0));
    let s = err_text(f.to_svg_string());
    assert!(
        s.contains("x range (5, 5)") && s.contains("smaller than hi"),
        "{s}"
    );

    let mut f = ok.clone();
    f.panels[0].x_range = Some((f64::NAN, 5.0));
    assert!(err_text(f.to_svg_string()).contains("finite"));
}

#[test]
fn bad_paths_and_extensions() {
    let fig = Figure::single(psd_panel());
    let dir = tempfile::tempdir().unwrap();
    let e = fig
        .save(dir.path().join("fig.jpg"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("'jpg'") && e.contains(".svg or .png"), "{e}");
    let e = fig.save(dir.path().join("fig")).unwrap_err().to_string();
    assert!(e.contains("extension ''"), "{e}");
    let e = fig
        .save_png(dir.path().join("fig.svg"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("'svg'"), "{e}");
    let missing = dir.path().join("no/such/dir/fig.svg");
    let e = fig.save(&missing).unwrap_err().to_string();
    assert!(
        e.contains("could not write") && e.contains("directory exists"),
        "{e}"
    );
    let e = fig
        .save(dir.path().join("no/such/dir/fig.png"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("could not write"), "{e}");
}

#[test]
fn enum_and_colour_parsing() {
    assert_eq!("LOG".parse::<Scale>().unwrap(), Scale::Log);
    assert_eq!("linear".parse::<Scale>().unwrap().to_string(), "linear");
    let e = "logarithmic".parse::<Scale>().unwrap_err().to_string();
    assert!(
        e.contains("'logarithmic'") && e.contains("linear, log"),
        "{e}"
    );
    let e = "star".parse::<Marker>().unwrap_err().to_string();
    assert!(
        e.contains("circle, cross, diamond, square, triangle"),
        "{e}"
    );
    assert_eq!("#D62728".parse::<Rgb>().unwrap(), Rgb::RED);
    assert_eq!("red".parse::<Rgb>().unwrap().to_string(), "#d62728");
    let e = "#12345".parse::<Rgb>().unwrap_err().to_string();
    assert!(e.contains("'#12345'") && e.contains("#rrggbb"), "{e}");
    assert!("#12345g".parse::<Rgb>().is_err());
}

#[test]
fn random_awkward_figures_always_render() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(2024);
    let specials = [
        0.0,
        -0.0,
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        1e-320,
        -1e300,
        1e308,
        f64::MAX,
        f64::MIN_POSITIVE,
    ];
    let value = |rng: &mut rand_chacha::ChaCha8Rng| -> f64 {
        if rng.gen_bool(0.1) {
            specials[rng.gen_range(0..specials.len())]
        } else {
            let mag = 10f64.powf(rng.gen_range(-40.0..40.0));
            rng.gen_range(-1.0..1.0) * mag
        }
    };
    let scales = [Scale::Linear, Scale::Log];
    for case in 0..60 {
        let n_panels = rng.gen_range(1..5);
        let mut panels = Vec::new();
        for _ in 0..n_panels {
            let mut p = Panel::new("random ζ", "x [?]", "y [?]")
                .with_scales(scales[rng.gen_range(0..2)], scales[rng.gen_range(0..2)]);
            p.legend = rng.gen_bool(0.5);
            if rng.gen_bool(0.2) {
                let a = rng.gen_range(0.001..10.0);
                p.x_range = Some((a, a * rng.gen_range(1.0001..1e6)));
            }
            for k in 0..rng.gen_range(0..4) {
                let n = if rng.gen_bool(0.1) {
                    rng.gen_range(5000..20000)
                } else {
                    rng.gen_range(0..50)
                };
                let constant = rng.gen_bool(0.15);
                let c = value(&mut rng);
                let x: Vec<f64> = (0..n)
                    .map(|_| if constant { c } else { value(&mut rng) })
                    .collect();
                let y: Vec<f64> = (0..n).map(|_| value(&mut rng)).collect();
                let style = match rng.gen_range(0..3) {
                    0 => SeriesStyle::Line {
                        width: rng.gen_range(1..5),
                        dashed: rng.gen_bool(0.3),
                    },
                    1 => SeriesStyle::Points {
                        size: rng.gen_range(1..8),
                        marker: Marker::Diamond,
                    },
                    _ => SeriesStyle::VLines {
                        dotted: rng.gen_bool(0.5),
                    },
                };
                let mut s = Series::line(x, y)
                    .with_style(style)
                    .with_alpha(rng.gen_range(0.0..=1.0));
                if rng.gen_bool(0.5) {
                    s.label = Some(format!("s{k} <&>"));
                }
                p.series.push(s);
            }
            panels.push(p);
        }
        let mut fig = Figure::grid(None, panels, rng.gen_range(1..4));
        // Cells from the smallest allowed size upwards.
        let (rows, cols) = fig.grid_shape();
        fig.width_px = (cols as u32 * rng.gen_range(160..500)).max(100);
        fig.height_px = (rows as u32 * rng.gen_range(120..400)).max(100);
        let svg = fig
            .to_svg_string()
            .unwrap_or_else(|e| panic!("case {case}: {e}"));
        assert!(!svg.contains("NaN"), "case {case}: NaN coordinate in SVG");
        if case % 6 == 0 {
            fig.render_rgb()
                .unwrap_or_else(|e| panic!("case {case}: {e}"));
        }
    }
}
