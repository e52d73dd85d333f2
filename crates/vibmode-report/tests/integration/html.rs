//! HTML report: escaping, figures, tables, self-containedness.

use vibmode_report::{escape_html, Figure, HtmlReport, Panel, Series};

fn small_figure(title: &str) -> Figure {
    let mut fig = Figure::single(
        Panel::new(title, "Time [s]", "a [m/s²]")
            .with_series(Series::line(vec![0.0, 1.0, 2.0], vec![0.0, 1.0, 0.5])),
    );
    fig.width_px = 400;
    fig.height_px = 300;
    fig
}

#[test]
fn escape_by_hand() {
    assert_eq!(
        escape_html("a<b & \"c\" 'd'>"),
        "a&lt;b &amp; &quot;c&quot; &#39;d&#39;&gt;"
    );
    assert_eq!(escape_html("ζ = 2 %"), "ζ = 2 %");
}

#[test]
fn all_text_is_escaped() {
    let mut r = HtmlReport::new("T <script>alert(1)</script>");
    r.heading(2, "H & <b>");
    r.paragraph("p <img src=x onerror=alert(1)>\nsecond line");
    r.preformatted("pre </pre><script>");
    r.table(&["<th>"], &[vec!["<td>&".into()]]);
    r.figure(&small_figure("fig <title>"), "cap <i>").unwrap();
    let html = r.to_html();
    assert!(!html.contains("<script"), "unescaped script tag");
    assert!(!html.contains("<img"));
    assert!(!html.contains("<b>") && !html.contains("<i>"));
    assert!(html.contains("<title>T &lt;script&gt;alert(1)&lt;/script&gt;</title>"));
    assert!(html.contains("<h2>H &amp; &lt;b&gt;</h2>"));
    assert!(html.contains("p &lt;img src=x onerror=alert(1)&gt;<br>\nsecond line"));
    assert!(html.contains("<pre>pre &lt;/pre&gt;&lt;script&gt;</pre>"));
    assert!(html.contains("<th>&lt;th&gt;</th>") && html.contains("<td>&lt;td&gt;&amp;</td>"));
    assert!(html.contains("Figure 1. cap &lt;i&gt;"));
    assert!(html.contains("fig &lt;title&gt;"), "SVG text escaped too");
}

#[test]
fn document_is_html5_and_self_contained() {
    let mut r = HtmlReport::new("Report");
    r.heading(9, "clamped");
    r.heading(0, "clamped too");
    r.figure(&small_figure("A"), "first").unwrap();
    let html = r.to_html();
    assert!(html.starts_with("<!DOCTYPE html>\n<html lang=\"en\">"));
    assert!(html.contains("<meta charset=\"utf-8\">") && html.contains("<style>"));
    assert!(html.trim_end().ends_with("</html>"));
    assert!(html.contains("<h6>clamped</h6>") && html.contains("<h1>clamped too</h1>"));
    for bad in ["<script", "<link", "src=\"", "href=", "@import", "url("] {
        assert!(!html.contains(bad), "external reference or script: {bad}");
    }
    // The only URL is the SVG namespace identifier.
    assert_eq!(
        html.matches("http").count(),
        html.matches("xmlns=\"http://www.w3.org/2000/svg\"").count()
    );
    // Balanced structure for the simple tags we emit.
    for tag in [
        "figure",
        "figcaption",
        "svg",
        "body",
        "head",
        "style",
        "h1",
        "h6",
    ] {
        assert_eq!(
            html.matches(&format!("<{tag}>")).count() + html.matches(&format!("<{tag} ")).count(),
            html.matches(&format!("</{tag}>")).count(),
            "tag {tag}"
        );
    }
}

#[test]
fn figure_count_and_numbering() {
    let mut r = HtmlReport::new("Figures");
    for k in 0..3 {
        r.figure(
            &small_figure(&format!("panel {k}")),
            &format!("caption {k}"),
        )
        .unwrap();
    }
    let html = r.to_html();
    assert_eq!(r.figure_count(), 3);
    assert_eq!(html.matches("<figure>").count(), 3);
    assert_eq!(html.matches("<svg ").count(), 3);
    assert!(html.contains("Figure 1. caption 0") && html.contains("Figure 3. caption 2"));
    // A bad figure is an error and is not counted.
    let mut bad = small_figure("bad");
    bad.columns = 0;
    assert!(r.figure(&bad, "x").is_err());
    assert_eq!(r.figure_count(), 3);
    assert_eq!(r.to_html().matches("<figure>").count(), 3);
}

#[test]
fn table_rendering() {
    let mut r = HtmlReport::new("Tables");
    r.table(
        &["Mode", "Frequency [Hz]", "Damping ratio [-]"],
        &[
            vec!["body bounce".into(), "1.10".into(), "0.21".into()],
            vec!["wheel hop".into(), "9.00".into()],
        ],
    );
    let html = r.to_html();
    assert_eq!(html.matches("<table>").count(), 1);
    assert_eq!(html.matches("<th>").count(), 3);
    assert_eq!(html.matches("<tr>").count(), 3, "header row + 2 rows");
    // Text left-aligned (plain <td>), numbers right-aligned (class "num"); short rows padded.
    assert_eq!(
        html.matches("<td>").count(),
        3,
        "two text cells and one padding cell"
    );
    assert_eq!(
        html.matches("<td class=\"num\">").count(),
        3,
        "three numbers"
    );
    assert!(html.contains("<tr><td>wheel hop</td><td class=\"num\">9.00</td><td></td></tr>"));
    assert!(html.contains("td.num{text-align:right"));
    assert!(html.contains("<th>Frequency [Hz]</th>"));
}

#[test]
fn save_writes_the_document_and_reports_bad_paths() {
    let dir = tempfile::tempdir().unwrap();
    let mut r = HtmlReport::new("Saved");
    r.paragraph("hello");
    let path = dir.path().join("report.html");
    r.save(&path).unwrap();
    assert_eq!(std::fs::read_to_string(&path).unwrap(), r.to_html());
    let e = r
        .save(dir.path().join("missing/report.html"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("could not write") && e.contains("report.html"),
        "{e}"
    );
}
