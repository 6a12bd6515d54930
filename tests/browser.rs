//! The study's `index.html` in real headless Chromium (Debian package `chromium`).
//!
//! The study runs into a temp folder on design 2, design 5 and a broken STL (so the page also
//! has failed designs; the study then exits 1). In Chromium, from `file://` with every host name
//! resolving to nothing, the page must
//! (a) list the designs of `<table id="ranking">` (`<tr data-id="…">`) in the order of the `id`
//!     column of `ranking.csv` next to it,
//! (b) have every `<img>` loaded (complete, `naturalWidth > 0`) after the load event,
//! (c) need no network: no `http(s)://` or `//` in `src`/`href` of `<img>`, `<script>`, `<link>`
//!     (and the like), and no non-`file:` resource fetched by the browser.
//! A full-page screenshot goes to `target/browser-check/index.png` for people to look at.
//!
//! How: a copy of the page, `.browser-check.html`, is written next to it (so relative paths
//! still resolve) with a small script appended that, on `load`, puts its findings in a
//! `<pre id="browser-check">` as URI-encoded JSON; `chromium --headless --dump-dom` prints the
//! DOM after the load event (`--virtual-time-budget`), and the test reads the findings back.
//! A second test runs the same check on a hand-written page with a broken and a remote image,
//! to prove the check catches them.
//!
//! Chromium: `$CHROMIUM`, else `chromium` on PATH, else (as root with apt-get) installed with
//! `apt-get install chromium`; otherwise the test fails and says so. Every Chromium run is
//! killed (its whole process group) after 60 s.

mod common;
use common::copy_design;
use std::ffi::OsString;
use std::os::unix::fs::PermissionsExt;
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

/// A Chromium run longer than this fails the test (the browser is killed).
const BROWSER_TIMEOUT: Duration = Duration::from_secs(60);
/// Layout width of the checks and of the screenshot.
const WIDTH: u32 = 1280;
/// The screenshot's height is the page's, within these bounds.
const MIN_HEIGHT: u32 = 800;
const MAX_HEIGHT: u32 = 16000;

// ---------------------------------------------------------------------------------------------
// Finding (or installing) Chromium

fn executable(path: &Path) -> bool {
    std::fs::metadata(path).is_ok_and(|m| m.is_file() && m.permissions().mode() & 0o111 != 0)
}

fn on_path(name: &str) -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|dir| dir.join(name))
        .find(|p| executable(p))
}

fn is_root() -> bool {
    // no libc here: the effective uid is the second field of the Uid line
    std::fs::read_to_string("/proc/self/status").is_ok_and(|s| {
        s.lines()
            .find_map(|l| l.strip_prefix("Uid:"))
            .and_then(|l| l.split_whitespace().nth(1).map(|u| u == "0"))
            .unwrap_or(false)
    })
}

const HOW_TO_INSTALL: &str = "install Debian's Chromium (`sudo apt-get install chromium`) or set \
     CHROMIUM to the path of a Chromium/Chrome binary";

fn find_or_install_chromium() -> Result<PathBuf, String> {
    if let Some(p) = std::env::var_os("CHROMIUM").filter(|p| !p.is_empty()) {
        let p = PathBuf::from(p);
        let resolved = if p.components().count() == 1 {
            on_path(&p.to_string_lossy())
        } else {
            Some(p.clone()).filter(|p| executable(p))
        };
        return resolved.ok_or_else(|| {
            format!(
                "CHROMIUM={} is not an executable file; {HOW_TO_INSTALL}",
                p.display()
            )
        });
    }
    if let Some(p) = on_path("chromium") {
        return Ok(p);
    }
    if !(is_root() && on_path("apt-get").is_some()) {
        return Err(format!(
            "Chromium not found (no CHROMIUM, no `chromium` on PATH) and not root with apt-get \
             to install it: {HOW_TO_INSTALL}"
        ));
    }
    eprintln!(
        "browser: `chromium` not found: installing Debian's chromium \
         (apt-get update -qq && apt-get install -y -qq chromium) …"
    );
    let start = Instant::now();
    let status = Command::new("sh")
        .args([
            "-c",
            "apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium",
        ])
        .stdout(Stdio::null())
        .status()
        .map_err(|e| format!("could not run apt-get: {e}; {HOW_TO_INSTALL}"))?;
    if !status.success() {
        return Err(format!(
            "`apt-get install chromium` failed ({status}); {HOW_TO_INSTALL}"
        ));
    }
    eprintln!(
        "browser: installed chromium in {:.1} s",
        start.elapsed().as_secs_f64()
    );
    on_path("chromium").ok_or_else(|| {
        format!("apt-get installed chromium but it is not on PATH; {HOW_TO_INSTALL}")
    })
}

/// Waits for `child` (started in its own process group) until `deadline`; past it, kills the
/// group (the browser and its helper processes) and returns `None`.
fn wait_or_kill(child: &mut Child, deadline: Instant) -> Option<ExitStatus> {
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return Some(status);
        }
        if Instant::now() > deadline {
            let _ = Command::new("kill")
                .args(["-KILL", "--", &format!("-{}", child.id())])
                .status();
            let _ = child.kill();
            let _ = child.wait();
            return None;
        }
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// `chromium --version`, or `None` if it does not answer within 10 s.
fn browser_version(browser: &Path) -> Option<String> {
    let out = tempfile::NamedTempFile::new().unwrap();
    let mut child = Command::new(browser)
        .arg("--version")
        .stdin(Stdio::null())
        .stdout(out.reopen().unwrap())
        .stderr(Stdio::null())
        .process_group(0)
        .spawn()
        .ok()?;
    wait_or_kill(&mut child, Instant::now() + Duration::from_secs(10))?;
    Some(
        std::fs::read_to_string(out.path())
            .unwrap_or_default()
            .trim()
            .to_string(),
    )
}

/// The browser, found or installed once for all tests of this file; a missing browser fails.
fn chromium() -> &'static Path {
    static BROWSER: OnceLock<Result<PathBuf, String>> = OnceLock::new();
    match BROWSER.get_or_init(|| {
        let found = find_or_install_chromium();
        if let Ok(p) = &found {
            let version = browser_version(p).unwrap_or_else(|| {
                panic!(
                    "`{} --version` did not answer within 10 s; {HOW_TO_INSTALL}",
                    p.display()
                )
            });
            eprintln!("browser: {} ({version})", p.display());
        }
        found
    }) {
        Ok(p) => p,
        Err(e) => panic!("{e}"),
    }
}

// ---------------------------------------------------------------------------------------------
// Running Chromium with a deadline

struct Run {
    stdout: String,
    stderr: String,
    elapsed: Duration,
}

/// The end of Chromium's stderr (for failure messages), without its D-Bus complaints.
fn stderr_tail(stderr: &str) -> String {
    let lines: Vec<&str> = stderr.lines().filter(|l| !l.contains("dbus")).collect();
    lines[lines.len().saturating_sub(15)..].join("\n")
}

/// Runs headless Chromium on `url` with `extra` flags, offline (every host name resolves to
/// nothing) and with a fresh profile; kills its process group after [`BROWSER_TIMEOUT`].
fn run_chromium(extra: &[String], url: &str, what: &str) -> Run {
    let browser = chromium();
    let scratch = tempfile::tempdir().unwrap();
    let profile = scratch.path().join("profile");
    std::fs::create_dir(&profile).unwrap();
    let out_path = scratch.path().join("stdout");
    let err_path = scratch.path().join("stderr");
    let mut args: Vec<OsString> = [
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-quic",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--hide-scrollbars",
        // (c): any http(s) fetch fails, so a page that needs the network shows it
        "--host-resolver-rules=MAP * ~NOTFOUND",
    ]
    .iter()
    .map(OsString::from)
    .collect();
    let mut profile_flag = OsString::from("--user-data-dir=");
    profile_flag.push(&profile);
    args.push(profile_flag);
    args.extend(extra.iter().map(OsString::from));
    args.push(url.into());
    let start = Instant::now();
    // output to files, not pipes: a helper process left behind cannot hold a read open
    let mut child = Command::new(browser)
        .args(&args)
        .stdin(Stdio::null())
        .stdout(std::fs::File::create(&out_path).unwrap())
        .stderr(std::fs::File::create(&err_path).unwrap())
        .process_group(0)
        .spawn()
        .unwrap_or_else(|e| panic!("could not start {}: {e}", browser.display()));
    let Some(status) = wait_or_kill(&mut child, start + BROWSER_TIMEOUT) else {
        let stderr = std::fs::read_to_string(&err_path).unwrap_or_default();
        panic!(
            "{what}: Chromium did not finish within {} s and was killed\n{}",
            BROWSER_TIMEOUT.as_secs(),
            stderr_tail(&stderr)
        );
    };
    let elapsed = start.elapsed();
    let stdout = String::from_utf8_lossy(&std::fs::read(&out_path).unwrap()).into_owned();
    let stderr = String::from_utf8_lossy(&std::fs::read(&err_path).unwrap()).into_owned();
    assert!(
        status.success(),
        "{what}: Chromium exited with {status}\n{}",
        stderr_tail(&stderr)
    );
    eprintln!("browser: {what}: {:.2} s", elapsed.as_secs_f64());
    Run {
        stdout,
        stderr,
        elapsed,
    }
}

fn file_url(path: &Path) -> String {
    let path = std::fs::canonicalize(path).unwrap();
    let mut url = String::from("file://");
    for b in path.to_str().expect("UTF-8 path").bytes() {
        if b.is_ascii_alphanumeric() || b"/-_.~".contains(&b) {
            url.push(b as char);
        } else {
            url.push_str(&format!("%{b:02X}"));
        }
    }
    url
}

// ---------------------------------------------------------------------------------------------
// The check in the browser

/// Runs on `load`; writes what it found as URI-encoded JSON (no HTML escaping to undo) into
/// `<pre id="browser-check">`.
const CHECK_SCRIPT: &str = r#"<script>
window.addEventListener("load", function () {
  var rows = Array.prototype.map.call(
    document.querySelectorAll("table#ranking tr[data-id]"),
    function (r) { return r.getAttribute("data-id"); });
  var images = Array.prototype.slice.call(document.images);
  var broken = images
    .filter(function (i) { return !i.complete || !(i.naturalWidth > 0); })
    .map(function (i) { return i.getAttribute("src"); });
  var fetched = (performance.getEntriesByType ? performance.getEntriesByType("resource") : [])
    .map(function (e) { return e.name; });
  var report = {
    ranking_table: document.querySelectorAll("table#ranking").length,
    rows: rows,
    images: images.length,
    broken: broken,
    fetched: fetched,
    height: Math.max(document.documentElement.scrollHeight, document.body.scrollHeight)
  };
  var pre = document.createElement("pre");
  pre.id = "browser-check";
  pre.textContent = encodeURIComponent(JSON.stringify(report));
  document.body.appendChild(pre);
});
</script>
"#;

/// What the page showed in Chromium.
#[derive(Debug)]
struct PageCheck {
    /// How many `<table id="ranking">` the page has.
    ranking_tables: u64,
    /// `data-id` of the ranking table's rows, in page order.
    rows: Vec<String>,
    images: u64,
    /// `src` of the images not loaded (incomplete or `naturalWidth` 0).
    broken: Vec<String>,
    /// Resources the browser fetched other than from `file:` (should be none).
    remote_fetches: Vec<String>,
    /// Document height at the check's layout width (px).
    height: u32,
    elapsed: Duration,
}

fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 2 < b.len() {
            let hex = std::str::from_utf8(&b[i + 1..i + 3]).unwrap();
            out.push(u8::from_str_radix(hex, 16).unwrap());
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    String::from_utf8(out).unwrap()
}

fn strings(v: &serde_json::Value) -> Vec<String> {
    v.as_array()
        .unwrap_or(&Vec::new())
        .iter()
        .map(|s| s.as_str().unwrap_or("(null)").to_string())
        .collect()
}

/// Loads `page` (next to which a `.browser-check.html` copy is written for the run) in
/// Chromium and reads back what the check script saw after the load event.
fn check_page(page: &Path) -> PageCheck {
    let html = std::fs::read_to_string(page).unwrap();
    let at = html
        .to_ascii_lowercase()
        .rfind("</body>")
        .unwrap_or(html.len());
    let copy = page.with_file_name(".browser-check.html");
    std::fs::write(
        &copy,
        format!("{}{CHECK_SCRIPT}{}", &html[..at], &html[at..]),
    )
    .unwrap();
    let run = run_chromium(
        &[
            format!("--window-size={WIDTH},1000"),
            "--virtual-time-budget=10000".into(),
            "--dump-dom".into(),
        ],
        &file_url(&copy),
        &format!("dump-dom {}", page.display()),
    );
    let _ = std::fs::remove_file(&copy);
    const OPEN: &str = "<pre id=\"browser-check\">";
    let found = run
        .stdout
        .rfind(OPEN)
        .map(|i| &run.stdout[i + OPEN.len()..])
        .and_then(|rest| rest.find("</pre>").map(|j| &rest[..j]));
    let Some(encoded) = found else {
        panic!(
            "{}: the check found nothing in the dumped DOM: the page's load event did not fire \
             (or the page's scripts broke the check) before Chromium dumped the DOM\n\
             stdout ({} bytes) ends: {}\nstderr: {}",
            page.display(),
            run.stdout.len(),
            &run.stdout[run.stdout.len().saturating_sub(500)..],
            stderr_tail(&run.stderr)
        );
    };
    let report: serde_json::Value = serde_json::from_str(&percent_decode(encoded)).unwrap();
    PageCheck {
        ranking_tables: report["ranking_table"].as_u64().unwrap(),
        rows: strings(&report["rows"]),
        images: report["images"].as_u64().unwrap(),
        broken: strings(&report["broken"]),
        remote_fetches: strings(&report["fetched"])
            .into_iter()
            .filter(|u| !u.starts_with("file:"))
            .collect(),
        height: report["height"].as_f64().unwrap_or(0.0) as u32,
        elapsed: run.elapsed,
    }
}

/// `src`/`href` values of resource-loading tags that point off the machine
/// (`http:`, `https:`, protocol-relative `//`). Plain `<a href>` links are not fetches.
fn remote_references(html: &str) -> Vec<String> {
    const TAGS: [&str; 8] = [
        "img", "script", "link", "iframe", "source", "embed", "object", "video",
    ];
    let lower = html.to_ascii_lowercase();
    let mut found = Vec::new();
    let mut pos = 0;
    while let Some(i) = lower[pos..].find('<') {
        let start = pos + i + 1;
        let end = lower[start..].find('>').map_or(lower.len(), |j| start + j);
        pos = end.min(lower.len());
        let tag = &lower[start..end];
        let name: String = tag
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric())
            .collect();
        if !TAGS.contains(&name.as_str()) {
            continue;
        }
        for attr in ["src", "href", "data", "srcset", "poster"] {
            let mut from = 0;
            while let Some(k) = tag[from..].find(&format!("{attr}=")) {
                let k = from + k;
                from = k + attr.len() + 1;
                let preceded_by_space = k > 0 && tag.as_bytes()[k - 1].is_ascii_whitespace();
                if !preceded_by_space {
                    continue;
                }
                let rest = &tag[from..];
                let value = match rest.chars().next() {
                    Some(q @ ('"' | '\'')) => rest[1..].split(q).next().unwrap_or(""),
                    _ => rest
                        .split(|c: char| c.is_ascii_whitespace())
                        .next()
                        .unwrap_or(""),
                };
                let value = value.trim();
                if value.starts_with("http:")
                    || value.starts_with("https:")
                    || value.starts_with("//")
                {
                    found.push(format!("<{name} {attr}=\"{value}\">"));
                }
            }
        }
    }
    found
}

fn target_dir() -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    match std::env::var_os("CARGO_TARGET_DIR").filter(|d| !d.is_empty()) {
        Some(d) => root.join(d),
        None => root.join("target"),
    }
}

/// A full-page screenshot of `page` (height `height`, clamped) to `png`; returns its size.
fn screenshot(page: &Path, height: u32, png: &Path) -> u64 {
    let _ = std::fs::remove_file(png);
    let height = height.clamp(MIN_HEIGHT, MAX_HEIGHT);
    run_chromium(
        &[
            format!("--window-size={WIDTH},{height}"),
            "--virtual-time-budget=10000".into(),
            format!("--screenshot={}", png.display()),
        ],
        &file_url(page),
        &format!("screenshot {WIDTH}x{height}"),
    );
    let size = std::fs::metadata(png)
        .unwrap_or_else(|e| panic!("no screenshot at {}: {e}", png.display()))
        .len();
    let head = std::fs::read(png).unwrap();
    assert!(
        head.starts_with(b"\x89PNG\r\n\x1a\n"),
        "{} is not a PNG",
        png.display()
    );
    size
}

// ---------------------------------------------------------------------------------------------
// The tests

/// The check itself on a hand-written page: it reads the row order, and it catches a missing
/// image and one that needs the network.
#[test]
fn the_browser_check_sees_rows_and_catches_broken_and_remote_images() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("sub")).unwrap();
    std::fs::write(
        dir.path().join("sub/good.svg"),
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="120" height="60"><rect width="120" height="60" fill="teal"/></svg>"#,
    )
    .unwrap();
    let page = dir.path().join("index.html");
    std::fs::write(
        &page,
        r#"<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>hand-made</title></head>
<body>
<table id="ranking">
  <tr><th>rank</th><th>design</th></tr>
  <tr data-id="design5"><td>1</td><td>Design 5</td></tr>
  <tr data-id="design2"><td>2</td><td>Design 2</td></tr>
</table>
<table><tr data-id="not-ranking"><td>another table</td></tr></table>
<img src="sub/good.svg" alt="good">
<img src="missing.svg" alt="missing">
<img src='https://example.com/remote.png' alt="remote">
<a href="https://example.com/">a link is not a fetch</a>
</body></html>
"#,
    )
    .unwrap();
    let check = check_page(&page);
    eprintln!("browser: hand-made page: {check:?}");
    assert_eq!(check.ranking_tables, 1);
    assert_eq!(check.rows, ["design5", "design2"]);
    assert_eq!(check.images, 3);
    assert_eq!(
        check.broken,
        ["missing.svg", "https://example.com/remote.png"]
    );
    assert_eq!(check.remote_fetches, ["https://example.com/remote.png"]);
    assert_eq!(
        remote_references(&std::fs::read_to_string(&page).unwrap()),
        ["<img src=\"https://example.com/remote.png\">"]
    );
    assert!(
        !dir.path().join(".browser-check.html").exists(),
        "the check's copy is cleaned up"
    );
    let png = dir.path().join("hand-made.png");
    let size = screenshot(&page, check.height, &png);
    assert!(size > 1000, "{} is {size} bytes", png.display());
}

/// The study's page on two designs and a broken one, in Chromium.
#[test]
fn the_study_page_works_offline_in_chromium_and_ranks_as_ranking_csv() {
    chromium(); // fail (or install) before the study's half minute
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let designs = tempfile::tempdir().unwrap();
    let out = tempfile::tempdir().unwrap();
    copy_design(&root.join("designs"), designs.path(), "design2");
    copy_design(&root.join("designs"), designs.path(), "design5");
    // a design that fails: the page then also reports failed designs
    std::fs::write(
        designs.path().join("broken.stl"),
        b"this is not an STL file \x00\x01\x02 at all",
    )
    .unwrap();
    let config = designs.path().join("coarse.toml");
    std::fs::write(&config, "[fem]\ntarget_error = 0.0\nmesh_size_mm = 5.0\n").unwrap();
    let start = Instant::now();
    let o = Command::new(env!("CARGO_BIN_EXE_rodstudy"))
        .args(["study", "--no-cache", "--designs"])
        .arg(designs.path())
        .arg("--out")
        .arg(out.path())
        .arg("--config")
        .arg(&config)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    // exit status 1: some design failed, the others are reported (src/cli/mod.rs)
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    eprintln!(
        "browser: study on 3 designs: {:.1} s",
        start.elapsed().as_secs_f64()
    );
    check_study_output(out.path(), 2);
}

/// Checks (a)–(c) on the study output in `out` (`index.html` and `ranking.csv`), with
/// `designs` ranked, and writes the screenshot.
fn check_study_output(out: &Path, designs: usize) {
    let page = out.join("index.html");
    let html = std::fs::read_to_string(&page).unwrap();

    let mut reader = csv::Reader::from_path(out.join("ranking.csv")).unwrap();
    let id_col = reader
        .headers()
        .unwrap()
        .iter()
        .position(|h| h == "id")
        .expect("ranking.csv has an `id` column");
    let ranking: Vec<String> = reader
        .records()
        .map(|r| r.unwrap()[id_col].to_string())
        .collect();
    assert_eq!(
        ranking.len(),
        designs,
        "the good designs are ranked: {ranking:?}"
    );

    let check = check_page(&page);
    eprintln!("browser: study page: {check:?}");

    // the screenshot first: people can look at it whatever fails below
    let shots = target_dir().join("browser-check");
    std::fs::create_dir_all(&shots).unwrap();
    let png = shots.join("index.png");
    let size = screenshot(&page, check.height, &png);
    eprintln!("browser: screenshot: {} ({size} bytes)", png.display());

    let mut problems = Vec::new();
    if check.ranking_tables != 1 {
        problems.push(format!(
            "(a) index.html has {} <table id=\"ranking\"> (expected 1)",
            check.ranking_tables
        ));
    }
    if check.rows != ranking {
        problems.push(format!(
            "(a) ranking order differs: the <tr data-id> rows of <table id=\"ranking\"> in \
             index.html are {:?}, the `id` column of ranking.csv is {ranking:?}",
            check.rows
        ));
    }
    if check.images == 0 {
        problems.push("(b) the page has no <img> at all".to_string());
    }
    if !check.broken.is_empty() {
        problems.push(format!(
            "(b) {} of {} images did not load in Chromium: {:?}",
            check.broken.len(),
            check.images,
            check.broken
        ));
    }
    let remote = remote_references(&html);
    if !remote.is_empty() {
        problems.push(format!("(c) index.html references the network: {remote:?}"));
    }
    if !check.remote_fetches.is_empty() {
        problems.push(format!(
            "(c) Chromium fetched from the network: {:?}",
            check.remote_fetches
        ));
    }
    if size <= 10_000 {
        problems.push(format!(
            "the screenshot {} is only {size} bytes (a blank page?)",
            png.display()
        ));
    }
    assert!(
        problems.is_empty(),
        "index.html in headless Chromium ({} ms to load and check):\n  {}\n(screenshot: {})",
        check.elapsed.as_millis(),
        problems.join("\n  "),
        png.display()
    );
}
