//! The `colcos` command line: any argument list (NUL-separated in the input) is parsed by the
//! binary's own clap definition (`colcos::cli`, the one the binary parses with) without a panic
//! (clap's debug checks of the definition included).
#![no_main]
use clap::Parser;
use colcos::cli::Cli;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let args = std::iter::once("colcos".to_string()).chain(
        data.split(|&b| b == 0)
            .map(|a| String::from_utf8_lossy(a).into_owned()),
    );
    if let Err(e) = Cli::try_parse_from(args) {
        // Rendering the message (usage, suggestions) is part of the handling.
        let _ = e.render().to_string();
    }
});
