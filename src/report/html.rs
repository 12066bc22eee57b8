//! A report's Markdown as one self-contained HTML page: rendered by pulldown-cmark (headings
//! with anchors, tables, a table of contents), each figure embedded where the text places it
//! as a `data:` URI. No script and no external resource: the page opens offline.

use pulldown_cmark::{html, CowStr, Event, Options, Parser, Tag, TagEnd};

/// A file the page embeds: its name as the Markdown refers to it, MIME type and bytes.
pub struct Embedded {
    /// File name as written in the Markdown (`![…](name)` or `src="name"`).
    pub file: String,
    /// MIME type (`image/png`, `image/svg+xml`).
    pub mime: &'static str,
    /// The file's bytes.
    pub bytes: Vec<u8>,
}

/// The page's style: readable text width, ruled tables that scroll when wide, figures at the
/// text's width with their captions.
const STYLE: &str = "body{font-family:'DejaVu Sans',Helvetica,Arial,sans-serif;max-width:1100px;\
margin:2em auto;padding:0 1em;line-height:1.45;color:#1b1b1b}\
h1{font-size:1.7em;border-bottom:2px solid #1f77b4;padding-bottom:.2em}\
h2{font-size:1.3em;margin-top:1.8em;border-bottom:1px solid #ccc}h3{font-size:1.1em}\
table{border-collapse:collapse;margin:1em 0;display:block;overflow-x:auto;max-width:100%}\
th,td{border:1px solid #ccc;padding:.25em .6em;text-align:left;vertical-align:top}\
th{background:#eef3f8}tr:nth-child(even) td{background:#fafafa}\
code{font-family:'DejaVu Sans Mono',monospace;font-size:.92em;background:#f3f3f3;padding:0 .2em}\
figure{margin:1.2em 0;text-align:center}figure img{max-width:100%;height:auto;border:1px solid #ddd}\
figcaption{font-size:.92em;color:#444;margin-top:.3em}\
nav.toc{background:#f6f8fa;border:1px solid #ddd;padding:.4em 1.2em;margin:1em 0}\
nav.toc ul{margin:.2em 0;padding-left:1.2em}nav.toc li.h3{margin-left:1.2em}\
details{margin:.3em 0 .6em 0}summary{cursor:pointer;color:#1f4e79}";

/// The anchor id for a heading's text: lower case, letters and digits kept, runs of anything
/// else one `-`; made unique among `taken` with a numeric suffix.
fn slug(text: &str, taken: &mut Vec<String>) -> String {
    let mut s = String::new();
    for c in text.chars().flat_map(char::to_lowercase) {
        if c.is_alphanumeric() {
            s.push(c);
        } else if !s.ends_with('-') && !s.is_empty() {
            s.push('-');
        }
    }
    let base = s.trim_end_matches('-').to_string();
    let base = if base.is_empty() {
        "section".into()
    } else {
        base
    };
    let mut id = base.clone();
    let mut k = 2;
    while taken.contains(&id) {
        id = format!("{base}-{k}");
        k += 1;
    }
    taken.push(id.clone());
    id
}

/// The `data:` URI of `f`.
fn data_uri(f: &Embedded) -> String {
    format!(
        "data:{};base64,{}",
        f.mime,
        super::explain::base64(&f.bytes)
    )
}

/// Raw HTML with every `src="file"` naming an embedded file replaced by its data URI.
fn embed_in_html(raw: &str, figures: &[Embedded]) -> String {
    let mut s = raw.to_string();
    for f in figures {
        let needle = format!("src=\"{}\"", f.file);
        if s.contains(&needle) {
            s = s.replace(&needle, &format!("src=\"{}\"", data_uri(f)));
        }
    }
    s
}

/// The page titled `title` for `markdown`, with `figures` embedded where the Markdown names
/// them and a table of contents (level-2 and level-3 headings) after the first heading.
pub fn page(title: &str, markdown: &str, figures: &[Embedded]) -> String {
    let opts = Options::ENABLE_TABLES | Options::ENABLE_STRIKETHROUGH;
    // the headings' texts, in order, for their ids and the contents
    let mut headings: Vec<(u8, String)> = Vec::new();
    let mut current: Option<(u8, String)> = None;
    for ev in Parser::new_ext(markdown, opts) {
        match ev {
            Event::Start(Tag::Heading { level, .. }) => {
                current = Some((level as u8, String::new()))
            }
            Event::Text(t) | Event::Code(t) => {
                if let Some((_, s)) = current.as_mut() {
                    s.push_str(&t);
                }
            }
            Event::End(TagEnd::Heading(_)) => headings.extend(current.take()),
            _ => {}
        }
    }
    let mut taken = Vec::new();
    let ids: Vec<String> = headings.iter().map(|h| slug(&h.1, &mut taken)).collect();
    let mut k = 0;
    let events = Parser::new_ext(markdown, opts).map(|ev| match ev {
        Event::Start(Tag::Heading {
            level,
            classes,
            attrs,
            ..
        }) => {
            let id = ids.get(k).cloned().unwrap_or_default();
            k += 1;
            Event::Start(Tag::Heading {
                level,
                id: Some(CowStr::from(id)),
                classes,
                attrs,
            })
        }
        Event::Start(Tag::Image {
            link_type,
            dest_url,
            title,
            id,
        }) => {
            let dest = match figures.iter().find(|f| *f.file == *dest_url) {
                Some(f) => CowStr::from(data_uri(f)),
                None => dest_url,
            };
            Event::Start(Tag::Image {
                link_type,
                dest_url: dest,
                title,
                id,
            })
        }
        Event::Html(raw) => Event::Html(CowStr::from(embed_in_html(&raw, figures))),
        Event::InlineHtml(raw) => Event::InlineHtml(CowStr::from(embed_in_html(&raw, figures))),
        other => other,
    });
    let mut body = String::new();
    html::push_html(&mut body, events);
    let contents: Vec<String> = headings
        .iter()
        .zip(&ids)
        .filter(|((level, _), _)| *level == 2 || *level == 3)
        .map(|((level, text), id)| {
            format!(
                "<li class=\"h{level}\"><a href=\"#{id}\">{}</a></li>",
                super::html_text(text)
            )
        })
        .collect();
    let toc = if contents.len() >= 3 {
        format!(
            "<nav class=\"toc\"><strong>Contents</strong><ul>{}</ul></nav>\n",
            contents.join("")
        )
    } else {
        String::new()
    };
    // the contents go after the first heading (the report's title)
    let body = match body.find("</h1>") {
        Some(i) => format!("{}{toc}{}", &body[..i + 5], &body[i + 5..]),
        None => format!("{toc}{body}"),
    };
    format!(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\
         <meta name=\"generator\" content=\"sinsmodel\"><title>{}</title>\
         <style>{STYLE}</style></head><body>\n{body}</body></html>\n",
        super::html_text(title)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn headings_tables_and_figures_are_rendered() {
        let md = "# Title\n\n## 1. First part\n\ntext with **bold** and `code`\n\n\
                  | a | b |\n|---|---|\n| 1 | 2 |\n\n## 2. Second\n\n\
                  <figure>\n<img src=\"fig.png\" alt=\"cap\">\n<figcaption>Figure 1. cap</figcaption>\n</figure>\n\n\
                  ## 2. Second\n\n![alt](other.png)\n";
        let figs = [
            Embedded {
                file: "fig.png".into(),
                mime: "image/png",
                bytes: vec![1, 2, 3],
            },
            Embedded {
                file: "other.png".into(),
                mime: "image/png",
                bytes: vec![4, 5, 6],
            },
        ];
        let p = page("T <x>", md, &figs);
        assert!(p.contains("<title>T &lt;x&gt;</title>"), "{p}");
        assert!(
            p.contains("<h2 id=\"1-first-part\">1. First part</h2>"),
            "{p}"
        );
        assert!(
            p.contains("<h2 id=\"2-second-2\">"),
            "duplicate heading ids: {p}"
        );
        assert!(p.contains("<table>") && p.contains("<td>2</td>"), "{p}");
        assert!(p.contains("<strong>bold</strong>") && p.contains("<code>code</code>"));
        assert!(p.contains("src=\"data:image/png;base64,AQID\""), "{p}");
        assert!(p.contains("src=\"data:image/png;base64,BAUG\""), "{p}");
        assert!(!p.contains("fig.png") && !p.contains("other.png"), "{p}");
        let toc = p.find("<nav class=\"toc\">").expect("contents");
        assert!(toc > p.find("</h1>").unwrap() && toc < p.find("<h2").unwrap());
        assert!(
            p.contains("<a href=\"#1-first-part\">1. First part</a>"),
            "{p}"
        );
        assert!(!p.contains("<script"), "no script in an offline page");
    }
}
