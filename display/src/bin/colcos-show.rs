//! `colcos-show IMAGE.png [--fullscreen] [--monitor N] [--at X,Y] [--no-decorations] [--seconds S]
//! [--no-vsync] [--headless OUT.png [--size WxH]]`: shows a PNG in the display window, or renders it
//! headless through the same pipeline. Used by the Xvfb screenshot test.
use colcos_display::{DisplayOptions, StillImage, render_headless, run_window};
use std::process::ExitCode;
use std::time::Duration;

fn main() -> ExitCode {
    match real_main() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn parse_pair<T: std::str::FromStr>(s: &str, sep: char) -> Result<(T, T), String> {
    let (a, b) = s
        .split_once(sep)
        .ok_or_else(|| format!("expected A{sep}B, got {s:?}"))?;
    Ok((
        a.trim()
            .parse()
            .map_err(|_| format!("bad number in {s:?}"))?,
        b.trim()
            .parse()
            .map_err(|_| format!("bad number in {s:?}"))?,
    ))
}

fn real_main() -> Result<(), String> {
    let mut args = std::env::args().skip(1);
    let mut opts = DisplayOptions {
        announce_first_frame: true,
        ..Default::default()
    };
    let (mut input, mut headless, mut size) = (None, None, None);
    while let Some(a) = args.next() {
        let mut val = || args.next().ok_or_else(|| format!("{a} needs a value"));
        match a.as_str() {
            "--fullscreen" => opts.fullscreen = true,
            "--monitor" => opts.monitor = Some(val()?.parse().map_err(|_| "bad --monitor")?),
            "--at" => opts.position = Some(parse_pair(&val()?, ',')?),
            "--no-decorations" => opts.decorations = false,
            "--no-vsync" => opts.vsync = false,
            "--seconds" => {
                opts.close_after = Some(Duration::from_secs_f64(
                    val()?.parse().map_err(|_| "bad --seconds")?,
                ))
            }
            "--headless" => headless = Some(val()?),
            "--size" => size = Some(parse_pair::<u32>(&val()?, 'x')?),
            _ if input.is_none() => input = Some(a.clone()),
            _ => return Err(format!("unexpected argument {a:?}")),
        }
    }
    let input = input.ok_or("usage: colcos-show IMAGE.png [options]")?;
    let img = image::open(&input)
        .map_err(|e| format!("{input}: {e}"))?
        .to_rgba8();
    if let Some(out) = headless {
        let shot =
            render_headless(&img, size.unwrap_or(img.dimensions())).map_err(|e| e.to_string())?;
        shot.save(&out).map_err(|e| format!("{out}: {e}"))?;
        return Ok(());
    }
    opts.window_size = size;
    run_window(opts, Box::new(StillImage::new(img))).map_err(|e| e.to_string())
}
