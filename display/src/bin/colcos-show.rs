//! `colcos-show IMAGE.png [--fullscreen] [--monitor N] [--at X,Y] [--no-decorations] [--seconds S]
//! [--no-vsync] [--headless OUT.png [--size WxH]]`: shows a PNG in the display window, or renders it
//! headless through the same pipeline. Used by the Xvfb screenshot test.
use clap::Parser;
use colcos_display::{DisplayOptions, StillImage, render_headless, run_window};
use std::process::ExitCode;
use std::time::Duration;

/// Shows a PNG in the colcos display window, or renders it headless through the same pipeline.
#[derive(Parser, Debug)]
#[command(name = "colcos-show")]
struct Args {
    /// The image to show.
    image: String,
    /// Borderless full screen on the monitor of `--monitor` (default: the primary one).
    #[arg(long)]
    fullscreen: bool,
    /// Index of the monitor (the window lists them when it opens).
    #[arg(long, value_name = "N")]
    monitor: Option<usize>,
    /// Window position, pixels.
    #[arg(long, value_name = "X,Y", value_parser = pair::<i32, ','>, allow_hyphen_values = true)]
    at: Option<(i32, i32)>,
    /// A window without a title bar.
    #[arg(long)]
    no_decorations: bool,
    /// Close after this many seconds.
    #[arg(long, value_name = "S")]
    seconds: Option<f64>,
    /// Present at once instead of waiting for the vertical blank.
    #[arg(long)]
    no_vsync: bool,
    /// Render to this PNG instead of opening a window.
    #[arg(long, value_name = "OUT.png")]
    headless: Option<String>,
    /// Window (or headless image) size, pixels (default: the image's).
    #[arg(long, value_name = "WxH", value_parser = pair::<u32, 'x'>)]
    size: Option<(u32, u32)>,
}

/// Parses `A<SEP>B` into two numbers.
fn pair<T: std::str::FromStr, const SEP: char>(s: &str) -> Result<(T, T), String> {
    let (a, b) = s
        .split_once(SEP)
        .ok_or_else(|| format!("expected A{SEP}B, got {s:?}"))?;
    let num = |v: &str| v.trim().parse().map_err(|_| format!("bad number in {s:?}"));
    Ok((num(a)?, num(b)?))
}

fn main() -> ExitCode {
    // The library's messages (monitors, adapter) reach the terminal as before it logged through `log`.
    env_logger::Builder::from_env(
        env_logger::Env::default().default_filter_or("colcos_display=info"),
    )
    .format(|buf, record| {
        use std::io::Write as _;
        writeln!(buf, "{}", record.args())
    })
    .init();
    match real_main(Args::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn real_main(args: Args) -> Result<(), String> {
    let input = args.image;
    let img = image::open(&input)
        .map_err(|e| format!("{input}: {e}"))?
        .to_rgba8();
    if let Some(out) = args.headless {
        let shot = render_headless(&img, args.size.unwrap_or(img.dimensions()))
            .map_err(|e| e.to_string())?;
        shot.save(&out).map_err(|e| format!("{out}: {e}"))?;
        return Ok(());
    }
    let opts = DisplayOptions {
        announce_first_frame: true,
        fullscreen: args.fullscreen,
        monitor: args.monitor,
        position: args.at,
        decorations: !args.no_decorations,
        vsync: !args.no_vsync,
        close_after: args.seconds.map(Duration::from_secs_f64),
        window_size: args.size,
        ..Default::default()
    };
    run_window(opts, Box::new(StillImage::new(img))).map_err(|e| e.to_string())
}
