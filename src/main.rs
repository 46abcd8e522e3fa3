//! The `colcos` command line.
use anyhow::Result;
use clap::Parser;
use colcos::cli::Cli;
use colcos::cmd::run_command;
use colcos::report::print_report;
use std::process::ExitCode;

fn main() -> ExitCode {
    colcos::run::quiet_wayland_probe();
    init_logging();
    match real_main() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", error_text(&e));
            ExitCode::FAILURE
        }
    }
}

/// The error and its causes on one line, each cause once: a library error that already ends with its
/// cause (`reading scenario x.toml: No such file ...`) does not get it again.
fn error_text(e: &anyhow::Error) -> String {
    let mut text = e.to_string();
    for cause in e.chain().skip(1) {
        let c = cause.to_string();
        if !text.ends_with(&c) {
            text.push_str(": ");
            text.push_str(&c);
        }
    }
    text
}

/// The libraries report through the `log` crate; their messages reach the terminal (stderr) at info
/// level unless `RUST_LOG` says otherwise. Dependencies such as wgpu stay quiet by default.
fn init_logging() {
    use std::io::Write as _;
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("colcos=info"))
        .format(|buf, record| match record.level() {
            log::Level::Info => writeln!(buf, "{}", record.args()),
            log::Level::Warn => writeln!(buf, "warning: {}", record.args()),
            level => writeln!(buf, "{}: {}", level.as_str().to_lowercase(), record.args()),
        })
        .init();
}

fn real_main() -> Result<()> {
    let mut out = String::new();
    let result = run_command(Cli::parse().command, &mut out);
    // What a refused or failed command measured before it stopped (pre-flight counts, a bridge's
    // summary) is printed too, then the error.
    print_report(&out)?;
    result
}
