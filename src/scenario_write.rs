//! Measured values written back into a scenario file in place: `toml_edit` keeps its comments, key
//! order and layout; the result is validated as a scenario before it replaces the file (written to a
//! temporary file beside it and renamed, so a crash leaves the old file or the new one, never half).
use anyhow::{Context, Result, bail};
use colcos_sim::scenario::Scenario;
use std::path::Path;
use toml_edit::{DocumentMut, Item, Table, value};

/// Sets `[section] key = v` for each `(section, key, v)` in the scenario file at `path`.
pub fn set_numbers(path: &Path, values: &[(&str, &str, f64)]) -> Result<()> {
    set_numbers_unless_changed(path, None, values)
}

/// [`set_numbers`], refused when `expected` is given and the file no longer holds it (edited while
/// a calibration ran: the measured values may no longer be meant for it).
pub fn set_numbers_unless_changed(
    path: &Path,
    expected: Option<&str>,
    values: &[(&str, &str, f64)],
) -> Result<()> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("reading the scenario {}", path.display()))?;
    if expected.is_some_and(|e| e != text) {
        bail!(
            "{}: the scenario changed while the calibration ran; nothing written (the measured values are in the calibration file)",
            path.display()
        );
    }
    let new = with_numbers(&text, values).with_context(|| format!("{}", path.display()))?;
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    Scenario::from_toml_str(&new, base).with_context(|| {
        format!(
            "{}: the scenario with the measured values is not valid",
            path.display()
        )
    })?;
    let tmp = path.with_extension("toml.tmp");
    std::fs::write(&tmp, new).with_context(|| format!("writing {}", tmp.display()))?;
    std::fs::rename(&tmp, path).with_context(|| format!("replacing {}", path.display()))?;
    Ok(())
}

/// `text` with `[section] key = v` set for each entry; a section that is missing is added at the end.
pub fn with_numbers(text: &str, values: &[(&str, &str, f64)]) -> Result<String> {
    let mut doc: DocumentMut = text.parse().context("not a TOML document")?;
    for &(section, key, v) in values {
        if !v.is_finite() {
            bail!("`{section}.{key}` = {v}: not a finite number");
        }
        // Three decimals: latencies are measured to the millisecond.
        let v = (v * 1e3).round() / 1e3;
        let root = doc.as_table_mut();
        if !root.contains_key(section) {
            root.insert(section, Item::Table(Table::new()));
        }
        let Some(table) = root.get_mut(section).and_then(Item::as_table_like_mut) else {
            bail!("`{section}` is not a table in the scenario file");
        };
        match table.get_mut(key) {
            Some(item) => {
                // Keep the comment or spacing that decorates the old value.
                let decor = item.as_value().map(|old| old.decor().clone());
                *item = value(v);
                if let (Some(decor), Some(new)) = (decor, item.as_value_mut()) {
                    *new.decor_mut() = decor;
                }
            }
            None => {
                table.insert(key, value(v));
            }
        }
    }
    Ok(doc.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_replace_in_place_keeping_comments_and_missing_sections_are_added() {
        let text =
            "name = \"x\"\n# the tracker\n[tracker]\nrate_hz = 30\nlatency = 0.04 # s, measured\n";
        let out = with_numbers(
            text,
            &[("tracker", "latency", 0.1234), ("rig", "latency", 0.05)],
        )
        .unwrap();
        assert!(
            out.contains("# the tracker\n[tracker]\nrate_hz = 30\n"),
            "{out}"
        );
        assert!(out.contains("latency = 0.123 # s, measured"), "{out}");
        assert!(out.contains("[rig]\nlatency = 0.05\n"), "{out}");
    }

    #[test]
    fn a_key_that_is_not_a_table_or_a_bad_value_is_refused() {
        let e = with_numbers("tracker = 3\n", &[("tracker", "latency", 0.1)]).unwrap_err();
        assert!(e.to_string().contains("`tracker` is not a table"), "{e}");
        let e = with_numbers("", &[("rig", "latency", f64::NAN)]).unwrap_err();
        assert!(e.to_string().contains("`rig.latency` = NaN"), "{e}");
    }

    #[test]
    fn the_file_is_replaced_only_by_a_valid_scenario() {
        let dir =
            std::env::temp_dir().join(format!("colcos-scenario-write-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("s.toml");
        std::fs::write(
            &path,
            "name = \"x\"\nduration = 1.0\n[tracker]\nlatency = 0.04\n",
        )
        .unwrap();
        set_numbers(&path, &[("tracker", "latency", 0.12)]).unwrap();
        let sc = Scenario::from_file(&path).unwrap();
        assert!((sc.spec.tracker.latency - 0.12).abs() < 1e-6);
        // A latency past what a scenario allows is refused and the file is left as it was.
        let before = std::fs::read_to_string(&path).unwrap();
        assert!(set_numbers(&path, &[("tracker", "latency", 50.0)]).is_err());
        assert_eq!(std::fs::read_to_string(&path).unwrap(), before);
        // A file edited since it was read is left alone.
        let e =
            set_numbers_unless_changed(&path, Some("name = \"x\"\n"), &[("rig", "latency", 0.03)])
                .unwrap_err();
        assert!(
            e.to_string().contains("changed while the calibration ran"),
            "{e}"
        );
        assert_eq!(std::fs::read_to_string(&path).unwrap(), before);
        set_numbers_unless_changed(&path, Some(&before), &[("rig", "latency", 0.03)]).unwrap();
        assert!((Scenario::from_file(&path).unwrap().spec.rig.latency - 0.03).abs() < 1e-6);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
