//! The explain report in a real browser: headless Chromium loads the `report.html` of a demo
//! run; the rendered DOM must hold tables, a table of contents whose links resolve, every
//! figure decoded with a non-zero size beside its caption, no raw Markdown in the visible text
//! and nothing wider than the window. A screenshot stays in `target/tmp/report_browser/` for a
//! person to look at. `tools/test` installs Debian's `chromium` and sets
//! `SINSMODEL_REQUIRE_BROWSER=1`, so in CI a missing browser fails the test; elsewhere it is
//! skipped with a message.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The browser: `SINSMODEL_CHROMIUM`, else the first of chromium, chromium-browser on PATH.
fn chromium() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("SINSMODEL_CHROMIUM") {
        return Some(PathBuf::from(p));
    }
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .flat_map(|d| ["chromium", "chromium-browser"].map(|n| d.join(n)))
        .find(|p| p.is_file())
}

/// Runs the browser headless on `url` with `extra` arguments (profile in `profile`); its
/// stdout. Killed after 120 s.
fn run_browser(browser: &Path, profile: &Path, extra: &[String], url: &str) -> String {
    let mut args: Vec<String> = [
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-quic",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--hide-scrollbars",
        "--virtual-time-budget=10000",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    args.push(format!("--user-data-dir={}", profile.display()));
    args.extend(extra.iter().cloned());
    args.push(url.to_string());
    // stdout into a file: a dumped DOM (figures inline) is larger than a pipe's buffer
    let dump = profile.with_extension("stdout");
    let mut child = Command::new(browser)
        .args(&args)
        .stdout(Stdio::from(
            std::fs::File::create(&dump).expect("the browser's stdout"),
        ))
        .stderr(Stdio::null())
        .spawn()
        .expect("start the browser");
    let start = Instant::now();
    loop {
        if child.try_wait().expect("wait for the browser").is_some() {
            break;
        }
        if start.elapsed() > Duration::from_secs(120) {
            let _ = child.kill();
            panic!("the browser did not finish within 120 s: {args:?}");
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    String::from_utf8_lossy(&std::fs::read(&dump).expect("the browser's stdout")).into_owned()
}

/// The checks, run in the page at its `load` event (every image loaded or failed); the result goes into the DOM as
/// JSON text inside `<pre id="sinsmodel-check">`.
const CHECK: &str = r#"<script>
window.addEventListener('load', () => {
  // synchronous: at 'load' every image has loaded (or failed); an awaited decode() runs in real
  // time, which the virtual-time budget does not wait for
  const imgs = Array.from(document.images);
  const text = document.body.innerText;
  const markers = ['**', '|---', '](', '![', '```', '`', '\n## ', '\n# ', '<figure', '&lt;'];
  const r = {
    tables: document.querySelectorAll('table').length,
    rows: document.querySelectorAll('td').length,
    h2: document.querySelectorAll('h2').length,
    toc: document.querySelectorAll('nav.toc a').length,
    toc_broken: Array.from(document.querySelectorAll('nav.toc a'))
      .filter(a => !document.getElementById(decodeURIComponent(a.getAttribute('href').slice(1))))
      .map(a => a.textContent),
    images: imgs.length,
    decoded: imgs.filter(i => i.complete && i.naturalWidth > 0 && i.naturalHeight > 0
      && i.getBoundingClientRect().width > 100).length,
    uncaptioned: imgs.filter(i => {
      const f = i.closest('figure');
      const c = f && f.querySelector('figcaption');
      return !c || c.textContent.trim().length < 10;
    }).length,
    raw_markdown: markers.filter(m => text.includes(m)),
    figure_numbers: Array.from(document.querySelectorAll('figcaption'))
      .map(c => parseInt((c.textContent.match(/^Figure (\d+)\./) || [0, -1])[1])),
    page_width: document.documentElement.scrollWidth,
    window_width: window.innerWidth,
  };
  const pre = document.createElement('pre');
  pre.id = 'sinsmodel-check';
  pre.textContent = JSON.stringify(r);
  document.body.appendChild(pre);
});
</script>"#;

#[test]
fn explain_report_renders_in_a_browser() {
    let Some(browser) = chromium() else {
        assert!(
            std::env::var_os("SINSMODEL_REQUIRE_BROWSER").is_none(),
            "no chromium on PATH (tools/test installs Debian's chromium)"
        );
        eprintln!("SKIPPED: no chromium on PATH; tools/test installs it");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("explain");
    let run = Command::new(env!("CARGO_BIN_EXE_sinsmodel"))
        .args(["explain", "--demo-seconds", "120", "--out"])
        .arg(&out)
        .output()
        .expect("run explain");
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    let checked = dir.path().join("check.html");
    std::fs::write(
        &checked,
        html.replace("</body>", &format!("{CHECK}</body>")),
    )
    .unwrap();
    let profile = dir.path().join("profile");
    let dom = run_browser(
        &browser,
        &profile,
        &["--dump-dom".into(), "--window-size=1280,1000".into()],
        &format!("file://{}", checked.display()),
    );
    let start = dom
        .find("<pre id=\"sinsmodel-check\">")
        .unwrap_or_else(|| panic!("the page's checks did not run; DOM: {:.2000}", dom));
    let json = &dom[start + 26..];
    let json = &json[..json.find("</pre>").expect("end of the checks")];
    let json = json
        .replace("&quot;", "\"")
        .replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&amp;", "&");
    let r: serde_json::Value =
        serde_json::from_str(&json).unwrap_or_else(|e| panic!("{e}: {json}"));
    let n = |k: &str| r[k].as_u64().unwrap_or_else(|| panic!("{k} in {r}"));
    assert!(n("tables") >= 3, "tables rendered: {r}");
    assert!(n("rows") >= 20, "table cells: {r}");
    assert!(n("h2") >= 5, "headings rendered: {r}");
    assert!(n("toc") >= 5, "a table of contents: {r}");
    assert_eq!(
        r["toc_broken"],
        serde_json::json!([]),
        "contents links: {r}"
    );
    assert!(n("images") >= 4, "figures: {r}");
    assert_eq!(
        n("decoded"),
        n("images"),
        "every figure decoded and shown: {r}"
    );
    assert_eq!(n("uncaptioned"), 0, "every figure beside its caption: {r}");
    let numbers: Vec<i64> = r["figure_numbers"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_i64().unwrap())
        .collect();
    let expected: Vec<i64> = (1..=numbers.len() as i64).collect();
    assert_eq!(numbers, expected, "figures numbered in page order: {r}");
    assert_eq!(
        r["raw_markdown"],
        serde_json::json!([]),
        "raw Markdown in the visible text: {r}"
    );
    assert!(
        n("page_width") <= n("window_width"),
        "nothing wider than the window: {r}"
    );
    // the screenshot, kept for a person
    let shots = Path::new(env!("CARGO_TARGET_TMPDIR")).join("report_browser");
    std::fs::create_dir_all(&shots).unwrap();
    let shot = shots.join("report.png");
    let _ = std::fs::remove_file(&shot);
    run_browser(
        &browser,
        &profile,
        &[
            format!("--screenshot={}", shot.display()),
            "--window-size=1280,2600".into(),
        ],
        &format!("file://{}", out.join("report.html").display()),
    );
    let png = std::fs::read(&shot).expect("a screenshot");
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    let (w, h) = (
        u32::from_be_bytes(png[16..20].try_into().unwrap()),
        u32::from_be_bytes(png[20..24].try_into().unwrap()),
    );
    assert!(w >= 1000 && h >= 2000, "screenshot {w}×{h}");
    assert!(
        png.len() > 50_000,
        "a page with content: {} bytes",
        png.len()
    );
    eprintln!("screenshot: {}", shot.display());
}
