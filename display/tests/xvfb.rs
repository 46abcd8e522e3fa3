//! The display window under X (Xvfb in CI): open it, take a screenshot of the screen, compare it with
//! the headless PNG of the same image. Skips (and says why) without DISPLAY, ImageMagick's `import` or a
//! GPU adapter, unless COLCOS_REQUIRE_DISPLAY=1 (CI), where a skip is a failure.
use colcos_display::{DisplayError, render_headless};
use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn skip(why: &str) {
    if std::env::var("COLCOS_REQUIRE_DISPLAY").is_ok_and(|v| v == "1") {
        panic!("COLCOS_REQUIRE_DISPLAY=1 but {why}");
    }
    eprintln!("skipping the display test: {why}");
}

/// Colour bars, gradients and single-pixel details: any scaling, filtering or colour conversion shows.
fn pattern(w: u32, h: u32) -> image::RgbaImage {
    image::RgbaImage::from_fn(w, h, |x, y| {
        let bar = (x * 8 / w) as u8;
        let r = if bar & 1 != 0 {
            255
        } else {
            (x * 255 / w) as u8
        };
        let g = if bar & 2 != 0 {
            200
        } else {
            (y * 255 / h) as u8
        };
        let b = if bar & 4 != 0 {
            37
        } else {
            ((x ^ y) & 0xff) as u8
        };
        image::Rgba([r, g, b, 255])
    })
}

fn screenshot(path: &std::path::Path) -> Result<(), String> {
    let out = Command::new("import")
        .args(["-window", "root"])
        .arg(path)
        .output()
        .map_err(|e| format!("import: {e}"))?;
    if !out.status.success() {
        return Err(format!(
            "import failed: {}",
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    Ok(())
}

fn show_and_capture(
    img_path: &std::path::Path,
    extra: &[&str],
    shot: &std::path::Path,
) -> Result<(), String> {
    let mut child = Command::new(env!("CARGO_BIN_EXE_colcos-show"))
        .arg(img_path)
        .args(extra)
        .args(["--seconds", "20"])
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .map_err(|e| e.to_string())?;
    let stdout = child.stdout.take().expect("piped");
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines().map_while(|l| l.ok()) {
            if line.contains("first frame presented") {
                let _ = tx.send(());
            }
        }
    });
    let started = Instant::now();
    let ready = rx.recv_timeout(Duration::from_secs(30)).is_ok();
    if !ready {
        let _ = child.kill();
        let _ = child.wait();
        return Err("the window did not present a frame within 30 s".into());
    }
    // Let a few more frames through, then capture.
    std::thread::sleep(Duration::from_millis(700));
    let r = screenshot(shot);
    let _ = child.kill();
    let _ = child.wait();
    eprintln!(
        "window up and captured in {:.1} s",
        started.elapsed().as_secs_f64()
    );
    r
}

/// A fresh folder for the images of test `name`, or why the window tests cannot run here (no X
/// display to open a window on, or no ImageMagick `import` to take a screenshot with).
fn shots_dir(name: &str) -> Result<std::path::PathBuf, &'static str> {
    if std::env::var_os("DISPLAY").is_none() {
        return Err("DISPLAY is not set (run under xvfb-run, see gpu/ci.sh)");
    }
    if Command::new("import").arg("-version").output().is_err() {
        return Err("ImageMagick's `import` is not installed (apt-get install imagemagick)");
    }
    let dir = std::env::temp_dir().join(format!("colcos-xvfb-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    Ok(dir)
}

fn check(name: &str, img: image::RgbaImage, extra: &[&str], whole_screen: bool) {
    let dir = match shots_dir(name) {
        Ok(dir) => dir,
        Err(why) => return skip(why),
    };
    let input = dir.join("input.png");
    img.save(&input).unwrap();
    let shot_path = dir.join("shot.png");
    if let Err(e) = show_and_capture(&input, extra, &shot_path) {
        return skip(&format!("the window could not be shown: {e}"));
    }
    let shot = image::open(&shot_path).unwrap().to_rgb8();
    let (w, h) = if whole_screen {
        shot.dimensions()
    } else {
        img.dimensions()
    };
    let headless = match render_headless(&img, (w, h)) {
        Ok(i) => i,
        Err(DisplayError::NoAdapter(e)) => return skip(&format!("no GPU adapter: {e}")),
        Err(e) => panic!("headless rendering failed: {e}"),
    };
    headless.save(dir.join("headless.png")).unwrap();
    assert!(
        shot.width() >= w && shot.height() >= h,
        "screenshot {}x{} smaller than {w}x{h}",
        shot.width(),
        shot.height()
    );
    let mut differ = 0;
    for y in 0..h {
        for x in 0..w {
            if shot.get_pixel(x, y) != headless.get_pixel(x, y) {
                differ += 1;
            }
        }
    }
    assert_eq!(
        differ,
        0,
        "{name}: {differ} of {} pixels differ between the screenshot and the headless PNG (see {})",
        w * h,
        dir.display()
    );
    eprintln!("{name}: screenshot of {w}x{h} identical to the headless PNG");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn windowed_screenshot_matches_headless_png() {
    check(
        "windowed",
        pattern(320, 180),
        &["--at", "0,0", "--no-decorations"],
        false,
    );
}

/// Borderless full screen: the image scaled by the largest factor that fits, black bars; the whole
/// screen must equal the headless rendering at the screen's size.
#[test]
fn fullscreen_screenshot_matches_headless_png() {
    check(
        "fullscreen",
        pattern(320, 180),
        &["--fullscreen", "--monitor", "0"],
        true,
    );
}

/// The window of Python's `render_mode="human"`: a `Viewer` fed from this thread, its event loop on
/// a display thread. The screenshot matches the headless PNG; a second viewer opens after the first
/// is closed (winit allows one event loop per process: the display thread serves both).
#[test]
fn viewer_screenshot_matches_headless_png_and_reopens() {
    use colcos_display::{DisplayOptions, Viewer};
    let dir = match shots_dir("viewer") {
        Ok(dir) => dir,
        Err(why) => return skip(why),
    };
    let opts = || DisplayOptions {
        position: Some((0, 0)),
        decorations: false,
        frame_period: Duration::from_millis(20),
        ..Default::default()
    };
    for round in 0..2 {
        let img = pattern(320 - 3 * round, 180);
        let size = img.dimensions();
        let mut v = match Viewer::open(opts(), size) {
            Ok(v) => v,
            Err(DisplayError::NoAdapter(e)) => return skip(&format!("no GPU adapter: {e}")),
            Err(e) => panic!("the viewer did not open: {e}"),
        };
        // Paced: five images take at least four frame periods.
        let t = Instant::now();
        for _ in 0..5 {
            assert!(v.show(img.as_raw().clone(), size));
        }
        assert!(
            t.elapsed() >= Duration::from_millis(75),
            "{:?}",
            t.elapsed()
        );
        let deadline = Instant::now() + Duration::from_secs(30);
        while v.presented() == 0 && Instant::now() < deadline {
            std::thread::sleep(Duration::from_millis(20));
        }
        assert!(v.presented() > 0, "round {round}: nothing presented");
        std::thread::sleep(Duration::from_millis(500));
        let shot_path = dir.join(format!("shot{round}.png"));
        screenshot(&shot_path).unwrap();
        let shot = image::open(&shot_path).unwrap().to_rgb8();
        let headless = render_headless(&img, size).unwrap();
        let mut differ = 0;
        for y in 0..size.1 {
            for x in 0..size.0 {
                if shot.get_pixel(x, y) != headless.get_pixel(x, y) {
                    differ += 1;
                }
            }
        }
        assert_eq!(
            differ,
            0,
            "round {round}: {differ} pixels differ (see {})",
            dir.display()
        );
        v.close();
        assert!(!v.is_open());
        assert!(!v.show(img.as_raw().clone(), size), "show after close");
        v.close();
    }
    let _ = std::fs::remove_dir_all(&dir);
}
