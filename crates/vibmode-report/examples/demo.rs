//! Renders a demonstration figure set (PSD with modes, stabilisation diagram, damping scatter,
//! time record) to `<out_dir>/demo.svg`, `demo.png` and `demo.html`.
//! Run: `cargo run -p vibmode-report --example demo -- /tmp`.
use vibmode_report::axes::rescale_to;
use vibmode_report::{Figure, HtmlReport, Marker, Panel, Rgb, Scale, Series, SeriesStyle};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args().nth(1).unwrap_or_else(|| ".".into());
    let fs_hz = 200.0;
    let n = 2048;
    let t_s: Vec<f64> = (0..n).map(|i| i as f64 / fs_hz).collect();
    let acc: Vec<f64> = t_s
        .iter()
        .map(|&t| {
            (2.0 * std::f64::consts::PI * 1.1 * t).sin()
                + 0.3 * (2.0 * std::f64::consts::PI * 9.0 * t).sin()
        })
        .collect();
    let f_hz: Vec<f64> = (0..=1024).map(|i| i as f64 * fs_hz / n as f64).collect();
    let psd: Vec<f64> = f_hz
        .iter()
        .map(|&f| {
            let a = 1.0 / ((1.0 - (f / 1.1f64).powi(2)).powi(2) + 0.04);
            let b = 0.05 / ((1.0 - (f / 9.0f64).powi(2)).powi(2) + 0.01);
            if f > 25.0 {
                1e-30
            } else {
                a + b
            }
        })
        .collect();
    let time = Panel::new("Record 1, FR spindle", "Time [s]", "Acceleration [m/s²]").with_series(
        Series::line(t_s, acc).with_style(SeriesStyle::Line {
            width: 1,
            dashed: false,
        }),
    );
    let spec = Panel::new(
        "Welch PSD and ARMA(20) model",
        "Frequency [Hz]",
        "PSD [(m/s²)²/Hz]",
    )
    .with_scales(Scale::Linear, Scale::Log)
    .with_x_range(0.0, 30.0)
    .with_series(Series::line(f_hz.clone(), psd.clone()).with_label("Welch"))
    .with_series(
        Series::line(f_hz.clone(), psd.iter().map(|p| p * 1.3).collect())
            .with_label("ARMA(20)")
            .with_style(SeriesStyle::Line {
                width: 2,
                dashed: true,
            }),
    )
    .with_series(
        Series::vlines(vec![1.1, 9.0])
            .with_label("modes")
            .with_color(Rgb::RED),
    );
    let mut orders = Vec::new();
    let mut freqs = Vec::new();
    for p in (2..=30).step_by(2) {
        for &f in &[1.1, 9.0, 3.0 + p as f64 * 0.3] {
            orders.push(p as f64);
            freqs.push(f + 0.02 * (p as f64).sin());
        }
    }
    let faint = rescale_to(&psd, Scale::Log, (0.0, 30.0));
    let stab = Panel::new("Stabilisation diagram", "Frequency [Hz]", "Model order p")
        .with_x_range(0.0, 25.0)
        .with_series(
            Series::line(f_hz.clone(), faint)
                .with_color(Rgb::GREY)
                .with_alpha(0.4),
        )
        .with_series(Series::points(freqs.clone(), orders, Marker::Cross).with_label("poles"));
    let damp = Panel::new(
        "Frequency vs damping",
        "Frequency [Hz]",
        "Damping ratio [-]",
    )
    .with_scales(Scale::Linear, Scale::Log)
    .with_series(
        Series::points(
            freqs.clone(),
            freqs.iter().map(|f| 0.01 + 0.02 * f.sin().abs()).collect(),
            Marker::Circle,
        )
        .with_label("ARMA"),
    )
    .with_series(
        Series::points(vec![1.2, 8.5], vec![0.2, 0.08], Marker::Diamond)
            .with_color(Rgb::RED)
            .with_label("physical model")
            .with_style(SeriesStyle::Points {
                size: 6,
                marker: Marker::Diamond,
            }),
    );
    let fig = Figure::grid(
        Some("Demo: bus suspension"),
        vec![time, spec, stab, damp],
        2,
    );
    fig.save(format!("{out}/demo.svg"))?;
    fig.save(format!("{out}/demo.png"))?;
    let mut rep = HtmlReport::new("Demo report");
    rep.paragraph("Four panels.");
    rep.figure(&fig, "Demo")?;
    rep.save(format!("{out}/demo.html"))?;
    Ok(())
}
