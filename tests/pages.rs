//! The HTML pages `specfx report` writes, checked as a reader sees them: every local link and
//! image exists, and in a real browser (headless Chromium) every image loads and no page is
//! wider than a 1280-pixel window.

mod common;
use common::specfx;

use std::path::{Path, PathBuf};
use std::process::Command;

/// The browser window the pages must fit.
const WINDOW: (u32, u32) = (1280, 1000);

/// The element the checker script adds to a page, holding its findings as JSON.
const MARK: &str = "specfx-check";

/// Runs in the page once everything has loaded: lists the images that failed to load and
/// the elements that reach past the window's right edge, and writes them into a `<pre>`.
const CHECKER: &str = r#"<script>
window.addEventListener('load', function () {
  var broken = [];
  document.querySelectorAll('img').forEach(function (img) {
    if (!img.complete || img.naturalWidth === 0) { broken.push(img.getAttribute('src')); }
  });
  var view = window.innerWidth;
  var wide = [];
  document.querySelectorAll('body *').forEach(function (e) {
    var r = e.getBoundingClientRect();
    if (r.right > view + 0.5 && wide.length < 10) {
      wide.push(e.tagName.toLowerCase() + ' reaching ' + Math.round(r.right) + ' px: ' +
        (e.textContent || e.getAttribute('src') || '').slice(0, 60));
    }
  });
  var pre = document.createElement('pre');
  pre.id = 'specfx-check';
  pre.textContent = JSON.stringify({
    broken: broken,
    scroll_width: document.documentElement.scrollWidth,
    inner_width: view,
    wide: wide
  });
  document.body.appendChild(pre);
});
</script>"#;

/// Every `href` and `src` attribute value in an HTML text (double-quoted, as specfx writes
/// them).
fn links(html: &str) -> Vec<String> {
    let mut out = Vec::new();
    for attr in [" href=\"", " src=\""] {
        let mut rest = html;
        while let Some(i) = rest.find(attr) {
            rest = &rest[i + attr.len()..];
            let end = rest.find('"').expect("a closing quote");
            out.push(rest[..end].replace("&amp;", "&"));
            rest = &rest[end..];
        }
    }
    out
}

/// The local files a page links that do not exist (relative to the page's directory).
fn missing_targets(page: &Path) -> Vec<String> {
    let html = std::fs::read_to_string(page).expect("a readable page");
    let dir = page.parent().expect("the page's directory");
    links(&html)
        .into_iter()
        .filter(|l| {
            let external = ["http://", "https://", "mailto:", "data:", "#"]
                .iter()
                .any(|p| l.starts_with(p));
            !external
        })
        .filter(|l| {
            let path = l.split(['#', '?']).next().unwrap_or("");
            !dir.join(path).exists()
        })
        .collect()
}

/// What the browser found on a page.
#[derive(Debug)]
struct Findings {
    broken_images: Vec<String>,
    scroll_width: u64,
    inner_width: u64,
    wide: Vec<String>,
}

fn chromium() -> String {
    for name in ["chromium", "chromium-browser", "google-chrome"] {
        let found = Command::new(name)
            .arg("--version")
            .output()
            .is_ok_and(|o| o.status.success());
        if found {
            return name.to_string();
        }
    }
    panic!(
        "headless Chromium is needed to check the report's pages and none was found \
         (apt-get install chromium; scripts/test installs it)"
    );
}

/// Opens a copy of the page (beside it, so relative links resolve) with the checker added,
/// in headless Chromium, and reads the findings back from the dumped DOM.
fn browse(page: &Path) -> Findings {
    let html = std::fs::read_to_string(page).expect("a readable page");
    let at = html.rfind("</body>").unwrap_or(html.len());
    let checked = format!("{}{CHECKER}{}", &html[..at], &html[at..]);
    let copy = page.with_file_name(format!(
        ".{MARK}-{}",
        page.file_name().unwrap().to_string_lossy()
    ));
    std::fs::write(&copy, checked).expect("the copy is written");
    let profile = tempfile::tempdir().expect("a browser profile directory");
    let out = Command::new(chromium())
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--hide-scrollbars",
            &format!("--user-data-dir={}", profile.path().display()),
            &format!("--window-size={},{}", WINDOW.0, WINDOW.1),
            "--virtual-time-budget=10000",
            "--dump-dom",
        ])
        .arg(format!("file://{}", copy.canonicalize().unwrap().display()))
        .output()
        .expect("chromium runs");
    std::fs::remove_file(&copy).expect("the copy is removed");
    let dom = String::from_utf8_lossy(&out.stdout);
    let open = format!("<pre id=\"{MARK}\">");
    let start = dom.find(&open).unwrap_or_else(|| {
        panic!(
            "{}: the checker left no findings (the page did not finish loading?); chromium said: {}",
            page.display(),
            String::from_utf8_lossy(&out.stderr)
        )
    }) + open.len();
    let end = start + dom[start..].find("</pre>").expect("the findings end");
    let json = dom[start..end]
        .replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&amp;", "&");
    let v: serde_json::Value = serde_json::from_str(&json).expect("the findings are JSON");
    let strings = |key: &str| -> Vec<String> {
        v[key]
            .as_array()
            .expect("a list")
            .iter()
            .map(|s| s.as_str().unwrap_or("").to_string())
            .collect()
    };
    Findings {
        broken_images: strings("broken"),
        scroll_width: v["scroll_width"].as_u64().expect("a width"),
        inner_width: v["inner_width"].as_u64().expect("a width"),
        wide: strings("wide"),
    }
}

/// Everything wrong with a page, one line per problem (empty: the page is fine).
fn problems(page: &Path) -> Vec<String> {
    let mut v: Vec<String> = missing_targets(page)
        .into_iter()
        .map(|t| format!("broken link: {t}"))
        .collect();
    let f = browse(page);
    v.extend(
        f.broken_images
            .iter()
            .map(|s| format!("image did not load: {s}")),
    );
    if f.scroll_width > f.inner_width {
        v.push(format!(
            "page is {} px wide in a {} px window: {}",
            f.scroll_width,
            f.inner_width,
            f.wide.join("; ")
        ));
    }
    v
}

fn html_pages(dir: &Path) -> Vec<PathBuf> {
    let mut pages = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).expect("a readable directory") {
            let p = entry.expect("an entry").path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|e| e == "html") {
                pages.push(p);
            }
        }
    }
    pages.sort();
    pages
}

#[test]
fn every_report_page_loads_whole_and_fits_the_window() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let o = specfx(&["report", "--out", dir.path().to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let pages = html_pages(dir.path());
    let names: Vec<String> = pages
        .iter()
        .map(|p| {
            p.strip_prefix(dir.path())
                .unwrap()
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    for want in [
        "index.html",
        "budget_baseline/budget.html",
        "stability/stability.html",
    ] {
        assert!(names.iter().any(|n| n == want), "{want} missing: {names:?}");
    }
    let mut all = Vec::new();
    for (page, name) in pages.iter().zip(&names) {
        all.extend(problems(page).into_iter().map(|p| format!("{name}: {p}")));
    }
    assert!(all.is_empty(), "{}", all.join("\n"));
}

#[test]
fn the_checker_finds_broken_links_and_images_and_overflow() {
    // A page with one of each problem, and a good image beside it.
    let dir = tempfile::tempdir().expect("a temporary directory");
    let png = specfx::report::chart::encode_png(&[255; 3 * 4], (2, 2)).unwrap();
    std::fs::write(dir.path().join("good.png"), png).unwrap();
    let cells: String = (0..60).map(|i| format!("<td>{i}.000000e-3</td>")).collect();
    let page = dir.path().join("bad.html");
    std::fs::write(
        &page,
        format!(
            "<!DOCTYPE html><html><head><meta charset=\"utf-8\"></head><body>\
             <a href=\"missing.txt\">x</a><a href=\"good.png\">ok</a><img src=\"good.png\">\
             <img src=\"gone.png\"><table><tr>{cells}</tr></table></body></html>"
        ),
    )
    .unwrap();
    let found = problems(&page);
    assert!(
        found.contains(&"broken link: missing.txt".to_string()),
        "{found:?}"
    );
    assert!(
        found.contains(&"broken link: gone.png".to_string()),
        "{found:?}"
    );
    assert!(
        found.contains(&"image did not load: gone.png".to_string()),
        "{found:?}"
    );
    assert!(
        found.iter().any(|p| p.starts_with("page is ")),
        "the 60-column table overflows: {found:?}"
    );
    assert_eq!(found.len(), 4, "the good image and link pass: {found:?}");
    // The same page without its problems passes.
    std::fs::write(
        &page,
        "<!DOCTYPE html><html><body><a href=\"good.png\">ok</a><img src=\"good.png\"></body></html>",
    )
    .unwrap();
    assert_eq!(problems(&page), Vec::<String>::new());
}
