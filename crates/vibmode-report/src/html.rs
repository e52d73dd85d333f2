//! A self-contained HTML5 report: inline CSS, inline SVG figures, no scripts, no external links.

use crate::error::ReportError;
use crate::model::Figure;
use std::fmt::Write as _;
use std::path::Path;

/// Escape text for HTML element content and attribute values (`& < > " '`).
pub fn escape_html(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            _ => out.push(c),
        }
    }
    out
}

/// Whether a table cell holds a number (right-aligned) rather than text (left-aligned): a
/// number, optionally signed, with a unit or percent sign after it, or a range `a-b` of numbers.
pub fn is_numeric_cell(cell: &str) -> bool {
    let t = cell.trim();
    let t = t.strip_suffix('%').map_or(t, str::trim_end);
    let first = t.split(' ').next().unwrap_or("");
    let parts: Vec<&str> = if first.len() > 1 && first[1..].contains('-') && !first.contains('e') {
        let (a, b) = first.split_at(first[1..].find('-').map_or(0, |i| i + 1));
        vec![a, &b[1..]]
    } else {
        vec![first]
    };
    !first.is_empty() && parts.iter().all(|p| p.parse::<f64>().is_ok())
}

const CSS: &str = "body{font-family:\"DejaVu Sans\",Verdana,Arial,sans-serif;max-width:1100px;\
margin:2em auto;padding:0 1em;color:#222;line-height:1.45}\
h1,h2,h3,h4,h5,h6{color:#113;margin-top:1.4em}\
figure{margin:1.5em 0;text-align:center}\
figure svg{max-width:100%;height:auto;border:1px solid #ddd}\
figcaption{font-size:0.92em;color:#444;margin-top:0.4em}\
table{border-collapse:collapse;margin:1em 0;font-size:0.95em}\
th,td{border:1px solid #bbb;padding:0.25em 0.6em;text-align:left}\
td.num{text-align:right;font-variant-numeric:tabular-nums}\
th{background:#eef}tr:nth-child(even) td{background:#f7f7f7}\
pre{background:#f4f4f4;border:1px solid #ddd;padding:0.6em;overflow-x:auto}";

/// Builder of a self-contained HTML5 report. Blocks appear in the order they are added; all
/// text is HTML-escaped.
#[derive(Debug, Clone, Default)]
pub struct HtmlReport {
    title: String,
    body: String,
    n_figures: usize,
    n_tables: usize,
}

/// Largest SVG the analysis report inlines in its page ([`HtmlReport::figure_or_image`]),
/// bytes: the demo's largest figure is 1.5 MB, an hour's frequency-damping figure 33 MB.
pub const INLINE_SVG_MAX_BYTES: usize = 8_000_000;

impl HtmlReport {
    /// A new, empty report; `title` goes into `<title>` and a top-level `<h1>`.
    pub fn new(title: &str) -> Self {
        HtmlReport {
            title: title.to_string(),
            ..Default::default()
        }
    }

    /// Add a heading; `level` is clamped to 1..=6.
    pub fn heading(&mut self, level: u8, text: &str) {
        let l = level.clamp(1, 6);
        let _ = writeln!(self.body, "<h{l}>{}</h{l}>", escape_html(text));
    }

    /// Add a paragraph of plain text (blank lines are kept as line breaks).
    pub fn paragraph(&mut self, text: &str) {
        let html = escape_html(text).replace('\n', "<br>\n");
        let _ = writeln!(self.body, "<p>{html}</p>");
    }

    /// Add a figure as inline SVG with a numbered caption ("Figure N. caption").
    pub fn figure(&mut self, fig: &Figure, caption: &str) -> Result<(), ReportError> {
        let svg = fig.to_svg_string()?;
        self.inline_svg(&svg, caption);
        Ok(())
    }

    /// [`HtmlReport::figure`], except that a figure whose SVG exceeds `max_inline_bytes`
    /// ([`INLINE_SVG_MAX_BYTES`] in the analysis report: every pole of an hour of records is
    /// tens of MB) is shown as the image `image_href` (a PNG of it the caller wrote, relative to
    /// the page) so that the page stays light; the caption says so.
    pub fn figure_or_image(
        &mut self,
        fig: &Figure,
        caption: &str,
        image_href: &str,
        max_inline_bytes: usize,
    ) -> Result<(), ReportError> {
        let svg = fig.to_svg_string()?;
        if svg.len() <= max_inline_bytes {
            self.inline_svg(&svg, caption);
            return Ok(());
        }
        self.n_figures += 1;
        let href = escape_html(image_href);
        let _ = writeln!(
            self.body,
            "<figure>\n<a href=\"{href}\"><img src=\"{href}\" alt=\"Figure {n}\" style=\"max-width:100%\"></a>\n<figcaption>Figure {n}. {} (Drawn as an image: its SVG has {:.1} MB, too much for the page; the SVG is beside the image.)</figcaption>\n</figure>",
            escape_html(caption),
            svg.len() as f64 / 1e6,
            n = self.n_figures,
        );
        Ok(())
    }

    fn inline_svg(&mut self, svg: &str, caption: &str) {
        // Drop any XML prolog so the SVG is a plain inline element.
        let svg = match svg.find("<svg") {
            Some(i) => &svg[i..],
            None => svg,
        };
        self.n_figures += 1;
        let _ = writeln!(
            self.body,
            "<figure>\n{}\n<figcaption>Figure {}. {}</figcaption>\n</figure>",
            svg.trim(),
            self.n_figures,
            escape_html(caption)
        );
    }

    /// Add a table. Rows shorter than `headers` are padded with empty cells; longer rows are kept
    /// whole.
    pub fn table(&mut self, headers: &[&str], rows: &[Vec<String>]) {
        self.n_tables += 1;
        let mut t = String::from("<table>\n<thead><tr>");
        for h in headers {
            let _ = write!(t, "<th>{}</th>", escape_html(h));
        }
        t.push_str("</tr></thead>\n<tbody>\n");
        for row in rows {
            t.push_str("<tr>");
            for cell in row {
                if is_numeric_cell(cell) {
                    let _ = write!(t, "<td class=\"num\">{}</td>", escape_html(cell));
                } else {
                    let _ = write!(t, "<td>{}</td>", escape_html(cell));
                }
            }
            for _ in row.len()..headers.len() {
                t.push_str("<td></td>");
            }
            t.push_str("</tr>\n");
        }
        t.push_str("</tbody>\n</table>\n");
        self.body.push_str(&t);
    }

    /// Add preformatted text (e.g. a parameter dump) in `<pre>`.
    pub fn preformatted(&mut self, text: &str) {
        let _ = writeln!(self.body, "<pre>{}</pre>", escape_html(text));
    }

    /// Number of figures added so far.
    pub fn figure_count(&self) -> usize {
        self.n_figures
    }

    /// The complete HTML5 document.
    pub fn to_html(&self) -> String {
        let t = escape_html(&self.title);
        format!(
            "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
<title>{t}</title>\n<style>{CSS}</style>\n</head>\n<body>\n<h1>{t}</h1>\n{}</body>\n</html>\n",
            self.body
        )
    }

    /// Write the document to `path` (UTF-8).
    pub fn save(&self, path: impl AsRef<Path>) -> Result<(), ReportError> {
        let path = path.as_ref();
        std::fs::write(path, self.to_html()).map_err(|e| ReportError::Write {
            path: path.to_path_buf(),
            message: e.to_string(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::is_numeric_cell;

    /// A figure whose SVG is above the limit is an image link (numbered like the others); at or
    /// below it, inline SVG.
    #[test]
    fn a_figure_too_large_to_inline_is_an_image() {
        use crate::{Figure, HtmlReport, Panel, Series};
        let x: Vec<f64> = (0..200).map(f64::from).collect();
        let fig = Figure::single(Panel::new("p", "x", "y").with_series(Series::line(x.clone(), x)));
        let size = fig.to_svg_string().unwrap().len();
        let mut r = HtmlReport::new("t");
        r.figure_or_image(&fig, "small", "figures/a.png", size)
            .unwrap();
        r.figure_or_image(&fig, "large & dense", "figures/b<1>.png", size - 1)
            .unwrap();
        let html = r.to_html();
        assert_eq!(html.matches("<figure>").count(), 2);
        assert_eq!(html.matches("<svg").count(), 1);
        assert!(
            html.contains("<img src=\"figures/b&lt;1&gt;.png\""),
            "{html}"
        );
        assert!(html.contains("Figure 2. large &amp; dense (Drawn as an image"));
        assert!(!html.contains("figures/a.png"));
    }

    #[test]
    fn numeric_cells_are_recognised() {
        for c in [
            "1.181",
            "-0.5",
            "85 %",
            "0.1578-0.2010",
            "+1.2 %",
            "1e-4",
            "12",
        ] {
            assert!(is_numeric_cell(c), "{c}");
        }
        for c in [
            "structural mode",
            "FR_sprung",
            "-",
            "",
            "record 01 (30.0 km/h)",
            "used",
        ] {
            assert!(!is_numeric_cell(c), "{c}");
        }
    }
}
