//! `specfx report`, the main job, run for real: the files and the summary it writes; a run on
//! two threads interrupted (SIGTERM, then SIGKILL) and resumed writes the bytes of one whole
//! run on one thread; and its HTML pages, checked as a reader sees them: every
//! local link and image exists, and in a real browser (headless Chromium) every image loads and
//! no page is wider than a 1280-pixel window.
//!
//! A report takes minutes: each thread count runs once ([`report`]) and the tests share it.

use crate::common::snapshot;

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::OnceLock;

/// One finished run of `specfx report`.
struct Run {
    dir: tempfile::TempDir,
    /// Its standard output, with the output directory's path replaced by `<out>`.
    stdout: String,
}

/// `specfx report`, run once per process for each of its two ways: `"1"` whole, in one run on
/// one rayon thread; `"2"` on two threads, interrupted twice and resumed ([`resumed_report`]).
fn report(threads: &'static str) -> &'static Run {
    static ONE: OnceLock<Run> = OnceLock::new();
    static TWO: OnceLock<Run> = OnceLock::new();
    match threads {
        "1" => ONE.get_or_init(|| {
            let dir = tempfile::tempdir().expect("a temporary directory");
            let out = dir.path().join("out");
            let o = report_command(&out)
                .env("RAYON_NUM_THREADS", "1")
                .output()
                .expect("specfx runs");
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
            finished(dir, &out, o.stdout)
        }),
        "2" => TWO.get_or_init(resumed_report),
        _ => unreachable!("one or two threads"),
    }
}

/// A finished report at `out` inside `dir`, and its stdout.
fn finished(dir: tempfile::TempDir, out: &Path, stdout: Vec<u8>) -> Run {
    let stdout = String::from_utf8(stdout)
        .expect("utf-8")
        .replace(out.to_str().unwrap(), "<out>");
    // The tests look at the report through `dir`.
    let inner = tempfile::tempdir().expect("a temporary directory");
    std::fs::remove_dir(inner.path()).unwrap();
    std::fs::rename(out, inner.path()).unwrap();
    drop(dir);
    Run { dir: inner, stdout }
}

/// `specfx report --out OUT --ladder 1 --stability-c-bits 12` on two rayon threads: the
/// trade-off's frontier at one budget (four algorithms reach 1 lsb8), not the default
/// ladder's six (minutes more; `tradeoff.rs` tests the frontier itself), and the stability
/// map's float paths at 2^12 + 1 cosines, not 2^15 + 1 (a quarter of its time; its default
/// grid is the same code on more cosines; `stability.rs` tests the map).
fn report_command(out: &Path) -> Command {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_specfx"));
    cmd.arg("report")
        .arg("--out")
        .arg(out)
        .args(["--ladder", "1", "--stability-c-bits", "12"]);
    cmd.env("RAYON_NUM_THREADS", "2");
    cmd
}

/// Asserts that two results hold the same files with the same bytes (`measured_*` files left
/// out: measured speed is the one thing allowed to differ).
fn assert_same_files(what: &str, a: &Path, b: &Path) {
    let (a, b) = (snapshot(a), snapshot(b));
    let names = |v: &[(PathBuf, Vec<u8>)]| {
        v.iter()
            .map(|f| f.0.clone())
            .collect::<std::collections::BTreeSet<_>>()
    };
    let (na, nb) = (names(&a), names(&b));
    assert!(
        na == nb,
        "{what}: different file sets: only in the first {:?}, only in the second {:?}",
        na.difference(&nb).collect::<Vec<_>>(),
        nb.difference(&na).collect::<Vec<_>>()
    );
    assert!(a.len() > 100, "{what}: {} files", a.len());
    for (x, y) in a.iter().zip(&b) {
        assert!(x.1 == y.1, "{what}: {} differs", x.0.display());
    }
}

#[test]
fn a_report_resumed_on_two_threads_is_the_bytes_of_one_run_on_one() {
    // Both ways at once, and at the same time (a report takes minutes, and the run on one
    // thread leaves the other core to the resumed run): a difference is a thread count or a
    // resume that changes a byte.
    let (one, two) = std::thread::scope(|s| {
        let two = s.spawn(|| report("2"));
        (report("1"), two.join().expect("the resumed report"))
    });
    assert_same_files(
        "whole on 1 thread, resumed on 2",
        one.dir.path(),
        two.dir.path(),
    );
    assert_eq!(one.stdout, two.stdout, "the summaries differ");
}

/// Starts `specfx report --out OUT` and, once a line of its stderr contains `at`, sends it
/// `signal` and waits for it; returns its stderr.
fn interrupt_at(out: &Path, at: &str, signal: libc::c_int) -> String {
    let mut child = report_command(out)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("specfx runs");
    let mut seen = String::new();
    let mut lines = BufReader::new(child.stderr.take().unwrap()).lines();
    for line in lines.by_ref() {
        let line = line.expect("utf-8 stderr");
        seen.push_str(&line);
        seen.push('\n');
        if line.contains(at) {
            // SAFETY: kill(2) on the child's pid; it has not been waited for, so the pid is its.
            let sent = unsafe { libc::kill(child.id() as libc::pid_t, signal) };
            assert_eq!(sent, 0, "kill");
            break;
        }
    }
    for line in lines {
        seen.push_str(&line.expect("utf-8 stderr"));
        seen.push('\n');
    }
    let status = child.wait().expect("specfx ends");
    assert!(!status.success(), "the run ended before '{at}': {seen}");
    seen
}

/// The staging directories beside `out` (`.out.partial-<pid>`).
fn staging_dirs(out: &Path) -> Vec<PathBuf> {
    let prefix = format!(".{}.partial-", out.file_name().unwrap().to_string_lossy());
    let mut v: Vec<PathBuf> = std::fs::read_dir(out.parent().unwrap())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            p.file_name()
                .unwrap()
                .to_string_lossy()
                .starts_with(&prefix)
        })
        .collect();
    v.sort();
    v
}

/// The checkpoints a staging directory holds, by step name.
fn checkpoints(staging: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(staging.join(".resume"))
        .map(|d| {
            d.map(|e| {
                e.unwrap()
                    .file_name()
                    .to_string_lossy()
                    .trim_end_matches(".json")
                    .to_string()
            })
            .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

/// The report on two threads, interrupted by SIGTERM as the error budget starts, then by
/// SIGKILL while the failures are mapped, and finished by a third run, each run checked on the
/// way: what it keeps, what it reuses, what it says.
fn resumed_report() -> Run {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let out = dir.path().join("out");
    // SIGTERM as the error budget starts: the synthesis is finished and kept.
    let first = interrupt_at(&out, "error budget of baseline", libc::SIGTERM);
    assert!(
        first.contains("run `specfx report --out") && first.contains("again to resume"),
        "{first}"
    );
    assert!(!out.exists(), "nothing at --out until the report is whole");
    let staged = staging_dirs(&out);
    assert_eq!(staged.len(), 1, "{staged:?}");
    assert_eq!(checkpoints(&staged[0]), ["costs"]);
    // The next run takes over, reuses the synthesis, and is killed (SIGKILL) while it maps the
    // failures: the trade-off is kept as well.
    let second = interrupt_at(&out, "mapping where", libc::SIGKILL);
    assert!(second.contains("resuming the interrupted run"), "{second}");
    assert!(second.contains("reusing 'costs'"), "{second}");
    assert!(!second.contains("reusing 'tradeoff'"), "{second}");
    assert!(!out.exists());
    let staged = staging_dirs(&out);
    assert_eq!(staged.len(), 1, "{staged:?}");
    assert_eq!(checkpoints(&staged[0]), ["costs", "tradeoff"]);
    // A file of a kept step changed behind the report's back: that step runs again (the
    // synthesis, whose tools' answers are cached), the other is reused.
    let txt = staged[0].join("cost_baseline.txt");
    let mut text = std::fs::read_to_string(&txt).unwrap();
    text.push('\n');
    std::fs::write(&txt, text).unwrap();
    // The third run finishes.
    let o = report_command(&out).output().expect("specfx runs");
    let third = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{third}");
    assert!(!third.contains("reusing 'costs'"), "{third}");
    assert!(third.contains("reusing 'tradeoff'"), "{third}");
    assert!(
        staging_dirs(&out).is_empty(),
        "the staging directory is gone"
    );
    assert!(!out.join(".resume").exists(), "no checkpoint in the result");
    finished(dir, &out, o.stdout)
}

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

/// Copies the files under `from` into `to` (an existing directory).
fn copy_tree(from: &Path, to: &Path) {
    for entry in std::fs::read_dir(from).expect("a readable directory") {
        let p = entry.expect("an entry").path();
        let target = to.join(p.file_name().unwrap());
        if p.is_dir() {
            std::fs::create_dir(&target).unwrap();
            copy_tree(&p, &target);
        } else {
            std::fs::copy(&p, &target).unwrap();
        }
    }
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
    // The checker writes a copy of each page beside it: it works on a copy of the report, which
    // other tests compare byte for byte meanwhile.
    let copy = tempfile::tempdir().expect("a temporary directory");
    copy_tree(report("2").dir.path(), copy.path());
    let dir = copy.path();
    let pages = html_pages(dir);
    let names: Vec<String> = pages
        .iter()
        .map(|p| p.strip_prefix(dir).unwrap().to_string_lossy().into_owned())
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

#[test]
fn report_writes_its_files_and_a_summary() {
    let run = report("2");
    let dir = run.dir.path();
    for name in [
        "paper.txt",
        "paper.json",
        "methods.csv",
        "coefficients.csv",
        "budget_baseline/budget.html",
        "budget_baseline/budget.json",
        "stability/stability.html",
        "stability/regions.csv",
        "stability/overview.png",
        "stability/heatmap_cs16_paper.png",
        "stability/heatmap_baseline.svg",
        "render/datapath.png",
        "render/diff_vs_cos_n.png",
        "render/render.md",
        "fit/fitted.toml",
        "fit/fitted_rom.v",
        "fit/fit.md",
        "fit/fitted.png",
        "furnace/furnace.md",
        "furnace/furnace_phong.png",
        "index.html",
    ] {
        let p = dir.join(name);
        assert!(p.is_file(), "{name} missing");
        assert!(std::fs::metadata(&p).unwrap().len() > 0, "{name} empty");
    }
    let out = &run.stdout;
    assert!(out.contains("printed claims reproduce"));
    assert!(out.contains("cs16_clamp"));
    let index = std::fs::read_to_string(dir.join("index.html")).unwrap();
    assert!(index.contains("href=\"budget_baseline/budget.html\""));
    assert!(index.contains("href=\"stability/stability.html\""));
    assert!(index.contains("src=\"render/datapath.png\""));
    assert!(index.contains("href=\"fit/fitted.toml\""));
    // The page opens with a verdict and has sections for cost and the cycle model. The
    // baseline is 4.36 lsb8 from cos^n (the paper's 1.70e-2 times 256), so it misses 1 lsb8.
    let verdict = index.find("<b>Verdict.</b>").expect("a verdict");
    assert!(verdict < index.find("<h2>").unwrap());
    assert!(
        index.contains("it does not meet a 1 lsb8 budget"),
        "{index}"
    );
    assert!(index.contains("<h2>The cycle model</h2>"));
    assert!(index.contains("src=\"furnace/furnace_phong.png\""));
    // The default fit serves only the scene's four exponents, within its budget.
    let fitted = specfx::pipeline::Config::from_toml(
        &std::fs::read_to_string(dir.join("fit/fitted.toml")).unwrap(),
    )
    .unwrap();
    assert_eq!(fitted.n.values(), &[16, 64, 256, 1024]);
    let fit: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("fit/fit.json")).unwrap()).unwrap();
    let total = |side: &str| fit[side]["analytic_total_luts"].as_u64().unwrap();
    assert!(total("fitted_cost") < total("generic_cost"), "{fit}");
    assert!(out.contains("fit (built-in scene"), "{out}");
    assert!(out.contains("furnace: 6 forms"), "{out}");
    assert!(out.contains("stability: "), "{out}");
    // The baseline's u8.16 coefficient holds coef(n) = 17 n / (32 pi) up to n = 1513.
    let regions = std::fs::read_to_string(dir.join("stability/regions.csv")).unwrap();
    assert!(
        regions.contains("baseline,fixed,unrepresentable,true,0,0,1514,4096,"),
        "{regions}"
    );
    let methods = std::fs::read_to_string(dir.join("methods.csv")).unwrap();
    assert_eq!(methods.lines().count(), 1 + 1009);
    // No temporary file is left behind.
    let leftovers: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
        .collect();
    assert!(leftovers.is_empty());
    // Every part records the version and the sha256 of its canonical inputs (checked here
    // with sha2); the index page ends with the report's own.
    use sha2::{Digest, Sha256};
    for (sub, command) in [
        (".", "report"),
        ("budget_baseline", "budget"),
        ("tradeoff", "tradeoff"),
        ("stability", "stability"),
        ("render", "render"),
        ("fit", "fit"),
        ("furnace", "furnace"),
        ("vectors_baseline", "vectors"),
    ] {
        let d = dir.join(sub);
        let p: serde_json::Value =
            serde_json::from_slice(&std::fs::read(d.join("provenance.json")).unwrap()).unwrap();
        let inputs = std::fs::read(d.join("inputs.toml")).unwrap();
        let hash: String = Sha256::digest(&inputs)
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect();
        assert_eq!(p["specfx_version"], env!("CARGO_PKG_VERSION"), "{sub}");
        assert_eq!(p["command"], command, "{sub}");
        assert_eq!(p["inputs_sha256"], hash.as_str(), "{sub}");
        if sub == "." {
            assert!(
                index.contains(&hash),
                "the index page names the report's inputs"
            );
        }
    }
}
