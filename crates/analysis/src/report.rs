//! One self-contained HTML report: headline numbers, sections with text, tables and figures
//! (PNG embedded as base64 `data:` URIs, SVG inlined), the configuration (JSON) and versions.
//! No external resources are referenced, so the file can be mailed or archived as is.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use base64::Engine as _;
use serde::{Deserialize, Serialize};

use crate::error::{AnalysisError, Result};

/// A table of preformatted cells.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Table {
    /// Caption above the table.
    pub caption: String,
    /// Column headers.
    pub header: Vec<String>,
    /// Rows of cells (each as long as `header`).
    pub rows: Vec<Vec<String>>,
}

/// A figure file to embed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Figure {
    /// Caption below the figure.
    pub caption: String,
    /// `.png` or `.svg` file.
    pub path: PathBuf,
}

/// A report section.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Section {
    /// Heading.
    pub heading: String,
    /// Paragraphs (plain text, escaped).
    pub paragraphs: Vec<String>,
    /// Tables.
    pub tables: Vec<Table>,
    /// Figures.
    pub figures: Vec<Figure>,
}

/// The whole report.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Report {
    /// Page title.
    pub title: String,
    /// Introductory paragraph.
    pub intro: String,
    /// Headline numbers as (name, value) pairs, shown first.
    pub headline: Vec<(String, String)>,
    /// Sections in order.
    pub sections: Vec<Section>,
    /// Configuration used (shown as pretty JSON).
    pub config: serde_json::Value,
    /// Software versions as (component, version) pairs.
    pub versions: Vec<(String, String)>,
}

/// Escapes `&`, `<`, `>`, `"` and `'` for HTML text and attributes.
pub fn escape_html(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => o.push_str("&amp;"),
            '<' => o.push_str("&lt;"),
            '>' => o.push_str("&gt;"),
            '"' => o.push_str("&quot;"),
            '\'' => o.push_str("&#39;"),
            _ => o.push(c),
        }
    }
    o
}

const STYLE: &str = "body{font-family:'DejaVu Sans',Helvetica,Arial,sans-serif;max-width:1500px;margin:24px auto;\
padding:0 24px;color:#222;line-height:1.45}h1{font-size:26px;border-bottom:2px solid #0072bd;padding-bottom:6px}\
h2{font-size:20px;margin-top:34px;color:#0b4f7c}table{border-collapse:collapse;margin:10px 0 18px}\
caption{text-align:left;font-weight:bold;padding:4px 0}th,td{border:1px solid #ccc;padding:4px 10px;\
text-align:right;font-variant-numeric:tabular-nums}th{background:#eef4f9}td:first-child,th:first-child{text-align:left}\
.headline{display:flex;flex-wrap:wrap;gap:12px;margin:16px 0}.kpi{border:1px solid #cfdde8;border-radius:6px;\
padding:8px 14px;background:#f6fafd}.kpi b{display:block;font-size:20px;color:#0072bd}figure{margin:14px 0 26px}\
figure img,figure svg{max-width:100%;height:auto;border:1px solid #e3e3e3}figcaption{font-size:14px;color:#555;\
margin-top:4px}pre{background:#f5f5f5;padding:10px;overflow:auto;font-size:13px}";

fn figure_html(f: &Figure) -> Result<String> {
    let io = |source| AnalysisError::Io {
        path: f.path.clone(),
        source,
    };
    let ext = f
        .path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let body = match ext.as_deref() {
        Some("png") => {
            let bytes = std::fs::read(&f.path).map_err(io)?;
            format!(
                "<img alt=\"{}\" src=\"data:image/png;base64,{}\">",
                escape_html(&f.caption),
                base64::engine::general_purpose::STANDARD.encode(bytes)
            )
        }
        Some("svg") => {
            let text = std::fs::read_to_string(&f.path).map_err(io)?;
            match text.find("<svg") {
                Some(i) => text[i..].to_string(),
                None => {
                    return Err(AnalysisError::Plot {
                        path: f.path.clone(),
                        message: "no <svg> element in the file".into(),
                    });
                }
            }
        }
        _ => {
            return Err(AnalysisError::Plot {
                path: f.path.clone(),
                message: "report figures must be .png or .svg".into(),
            });
        }
    };
    Ok(format!(
        "<figure>{body}<figcaption>{}</figcaption></figure>\n",
        escape_html(&f.caption)
    ))
}

fn table_html(t: &Table) -> String {
    let mut s = String::from("<table>");
    if !t.caption.is_empty() {
        let _ = write!(s, "<caption>{}</caption>", escape_html(&t.caption));
    }
    s.push_str("<tr>");
    for h in &t.header {
        let _ = write!(s, "<th>{}</th>", escape_html(h));
    }
    s.push_str("</tr>");
    for r in &t.rows {
        s.push_str("<tr>");
        for c in r {
            let _ = write!(s, "<td>{}</td>", escape_html(c));
        }
        s.push_str("</tr>");
    }
    s.push_str("</table>\n");
    s
}

impl Report {
    /// Renders the page. Figures are read from disk and embedded.
    ///
    /// # Errors
    /// [`AnalysisError::Io`] naming an unreadable figure, [`AnalysisError::Plot`] for a figure
    /// that is neither PNG nor SVG, [`AnalysisError::Json`].
    pub fn to_html(&self) -> Result<String> {
        let mut s = String::new();
        let _ = write!(
            s,
            "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{}</title><style>{STYLE}</style></head><body>\n<h1>{}</h1>\n",
            escape_html(&self.title),
            escape_html(&self.title)
        );
        if !self.intro.is_empty() {
            let _ = writeln!(s, "<p>{}</p>", escape_html(&self.intro));
        }
        if !self.headline.is_empty() {
            s.push_str("<div class=\"headline\">");
            for (k, v) in &self.headline {
                let _ = write!(
                    s,
                    "<div class=\"kpi\"><b>{}</b>{}</div>",
                    escape_html(v),
                    escape_html(k)
                );
            }
            s.push_str("</div>\n");
        }
        for sec in &self.sections {
            let _ = writeln!(s, "<h2>{}</h2>", escape_html(&sec.heading));
            for p in &sec.paragraphs {
                let _ = writeln!(s, "<p>{}</p>", escape_html(p));
            }
            for t in &sec.tables {
                s.push_str(&table_html(t));
            }
            for f in &sec.figures {
                s.push_str(&figure_html(f)?);
            }
        }
        s.push_str("<h2>Configuration</h2>\n");
        let _ = writeln!(
            s,
            "<pre>{}</pre>",
            escape_html(&serde_json::to_string_pretty(&self.config)?)
        );
        if !self.versions.is_empty() {
            s.push_str(&table_html(&Table {
                caption: "Versions".into(),
                header: vec!["component".into(), "version".into()],
                rows: self
                    .versions
                    .iter()
                    .map(|(a, b)| vec![a.clone(), b.clone()])
                    .collect(),
            }));
        }
        s.push_str("</body></html>\n");
        Ok(s)
    }

    /// Renders and writes the page atomically to `path`.
    ///
    /// # Errors
    /// As [`Report::to_html`], plus [`AnalysisError::Io`] naming `path`.
    pub fn write(&self, path: &Path) -> Result<()> {
        let html = self.to_html()?;
        flapssm_data::atomic::write_bytes_atomic(path, html.as_bytes()).map_err(|source| {
            AnalysisError::Io {
                path: path.to_path_buf(),
                source,
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_markup() {
        assert_eq!(
            escape_html("a<b & \"c\">'"),
            "a&lt;b &amp; &quot;c&quot;&gt;&#39;"
        );
    }
}
