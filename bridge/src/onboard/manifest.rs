//! The manifest `colcos.onboard.export_c` writes beside the C: the policy's hash, its C prefix and
//! source, and its runtime parameter defaults. Read strictly: a bad file is refused naming
//! `rig.onboard`, the file and the field.
use super::{RUNTIME_LEN, positive_slot};
use colcos_sim::error::{Result, SimError};
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// Largest manifest read, bytes.
const MAX_MANIFEST_BYTES: u64 = 1 << 20;

/// The format this bridge reads.
pub(crate) const FORMAT: &str = "colcos-onboard-policy/1";

/// The encoding the policy was exported with (the simulator's sensor model and wheel limit).
#[derive(Clone, Debug, PartialEq, Deserialize)]
pub struct ManifestEncoding {
    pub gamma: f64,
    pub crosstalk: [[f64; 3]; 3],
    pub gain: f64,
    pub integration_ms: f64,
    pub dark_counts: f64,
    pub max_wheel_speed: f64,
    pub bumper_span: f64,
    pub dt: f64,
}

#[derive(Clone, Debug, PartialEq, Deserialize)]
pub struct OnboardManifest {
    pub format: String,
    /// The C names' prefix (`<prefix>_step_with`, ...).
    pub prefix: String,
    /// The network's hash, as `PRN` names it and the robot's telemetry echoes it.
    pub hash: u32,
    /// The C source and header, relative to the manifest.
    pub source: String,
    pub header: String,
    pub layer_sizes: Vec<usize>,
    pub activations: Vec<String>,
    /// The runtime parameter block the policy was exported with.
    pub runtime_defaults: Vec<f32>,
    pub encoding: ManifestEncoding,
    /// The directory the manifest was read from.
    #[serde(skip)]
    pub dir: PathBuf,
}

impl OnboardManifest {
    /// Reads and checks `path`.
    pub fn load(path: &Path) -> Result<OnboardManifest> {
        let bad = |why: String| SimError::invalid("rig.onboard", path.display(), why);
        // A manifest is a few KB; a path to anything else must not be read whole.
        let len = std::fs::metadata(path)
            .map_err(|e| bad(format!("cannot read it: {e}")))?
            .len();
        if len > MAX_MANIFEST_BYTES {
            return Err(bad(format!(
                "{len} bytes: not an on-board policy manifest (at most {MAX_MANIFEST_BYTES})"
            )));
        }
        let text =
            std::fs::read_to_string(path).map_err(|e| bad(format!("cannot read it: {e}")))?;
        let mut m: OnboardManifest = serde_json::from_str(&text).map_err(|e| {
            bad(format!(
                "not an on-board policy manifest (colcos.onboard.export_c writes one): {e}"
            ))
        })?;
        m.dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        m.check().map_err(bad)?;
        Ok(m)
    }

    fn check(&self) -> std::result::Result<(), String> {
        if self.format != FORMAT {
            return Err(format!(
                "`format` = {:?}: this bridge reads {FORMAT:?}",
                self.format
            ));
        }
        let ident = |s: &str| {
            s.chars()
                .next()
                .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
                && s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
        };
        if !ident(&self.prefix) {
            return Err(format!("`prefix` = {:?}: not a C identifier", self.prefix));
        }
        if self.runtime_defaults.len() != RUNTIME_LEN {
            return Err(format!(
                "`runtime_defaults` has {} values: expected {RUNTIME_LEN}",
                self.runtime_defaults.len()
            ));
        }
        for (i, v) in self.runtime_defaults.iter().enumerate() {
            if !v.is_finite() || (positive_slot(i) && *v <= 0.0) {
                return Err(format!(
                    "`runtime_defaults[{i}]` = {v}: must be finite{}",
                    if positive_slot(i) { " and > 0" } else { "" }
                ));
            }
        }
        if self.layer_sizes.first() != Some(&17) || self.layer_sizes.last() != Some(&2) {
            return Err(format!(
                "`layer_sizes` = {:?}: an on-board policy maps 17 observations to 2 wheel speeds",
                self.layer_sizes
            ));
        }
        Ok(())
    }

    /// The scenario's `[rig] onboard` (relative to its directory), if it names one.
    pub fn of_scenario(
        scenario: &colcos_sim::scenario::Scenario,
    ) -> Result<Option<OnboardManifest>> {
        match &scenario.spec.rig.onboard {
            Some(p) => OnboardManifest::load(&scenario.base_dir.join(p)).map(Some),
            None => Ok(None),
        }
    }

    /// The C source's path.
    pub fn source_path(&self) -> PathBuf {
        self.dir.join(&self.source)
    }
}
