//! What the command line prints when a command is done.
use anyhow::{Context, Result};
use std::io::Write;

/// Prints a command's report on stdout. A reader that went away (`colcos run ... | grep -q`) is not
/// an error: `println!` would panic on the broken pipe after the command's files were written.
pub fn print_report(text: &str) -> Result<()> {
    match std::io::stdout().lock().write_all(text.as_bytes()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(e).context("writing the report to stdout")
        }
        _ => Ok(()),
    }
}
