//! `colcos behaviours`: the behaviours a robot group can name, with the keys of their `params`.
use anyhow::Result;
use colcos_sim::behaviour::registry;
use std::fmt::Write as _;

pub fn main(text: &mut String) -> Result<()> {
    writeln!(
        text,
        "A robot group names one with `behaviour = \"NAME\"` and sets its keys in `params = {{ ... }}`."
    )?;
    for (name, about) in registry::list() {
        writeln!(text, "\n{name}: {about}")?;
        for p in registry::params(name).unwrap_or_default() {
            writeln!(
                text,
                "  {:18} {:24} default {:6} {}",
                p.name, p.ty, p.default, p.meaning
            )?;
        }
    }
    Ok(())
}
