//! The exported C, compiled for this machine and loaded, so the twin's robots run the very code that
//! goes on the real ones (firmware in the loop). Built with `$CC` (default `cc`) as
//! `-std=c99 -O2 -shared -fPIC`: the flags the export's header asks for (no fast-math).
use super::{OnboardManifest, RUNTIME_LEN};
use colcos_sim::error::{Result, SimError};
use libloading::Library;
use std::path::PathBuf;
use std::process::Command;

type DefaultParams = unsafe extern "C" fn(*mut f32);
type WriteParams = unsafe extern "C" fn(*mut f32, u16, u8, *const f32) -> i32;
type EncodeWith =
    unsafe extern "C" fn(*const f32, *const u16, *const u16, *const u16, f32, f32, *mut f32);
type StepWith =
    unsafe extern "C" fn(*const f32, *const u16, *const u16, *const u16, *mut f32, *mut f32);

pub struct OnboardFirmware {
    default_params: DefaultParams,
    write_params: WriteParams,
    encode_with: EncodeWith,
    step_with: StepWith,
    hash: u32,
    // Last: the functions above point into it.
    _lib: Library,
}

impl OnboardFirmware {
    /// Compiles and loads the manifest's C source.
    pub fn build(manifest: &OnboardManifest) -> Result<OnboardFirmware> {
        let source = manifest.source_path();
        let bad = |why: String| SimError::invalid("rig.onboard", source.display(), why);
        if !source.is_file() {
            return Err(bad(
                "the policy's C source is missing (export_c writes it beside the manifest)".into(),
            ));
        }
        let lib_path = scratch_path(manifest.hash);
        let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
        let out = Command::new(&cc)
            .args(["-std=c99", "-O2", "-shared", "-fPIC", "-o"])
            .arg(&lib_path)
            .arg(&source)
            .arg("-lm")
            .output()
            .map_err(|e| bad(format!("cannot run the C compiler `{cc}` (set CC): {e}")))?;
        if !out.status.success() {
            let _ = std::fs::remove_file(&lib_path);
            return Err(bad(format!(
                "`{cc}` failed: {}",
                String::from_utf8_lossy(&out.stderr).trim()
            )));
        }
        // SAFETY: the library is the export's C, just compiled: no initialisers beyond libc's; the
        // symbols are looked up with the signatures its header declares.
        let loaded = unsafe {
            Library::new(&lib_path).and_then(|lib| {
                let p = &manifest.prefix;
                let default_params: DefaultParams =
                    *lib.get(format!("{p}_default_params\0").as_bytes())?;
                let write_params: WriteParams =
                    *lib.get(format!("{p}_write_params\0").as_bytes())?;
                let encode_with: EncodeWith = *lib.get(format!("{p}_encode_with\0").as_bytes())?;
                let step_with: StepWith = *lib.get(format!("{p}_step_with\0").as_bytes())?;
                Ok((lib, default_params, write_params, encode_with, step_with))
            })
        };
        // Mapped once loaded: the file itself is not needed any more.
        let _ = std::fs::remove_file(&lib_path);
        let (lib, default_params, write_params, encode_with, step_with) =
            loaded.map_err(|e| bad(format!("cannot load the compiled policy: {e}")))?;
        let fw = OnboardFirmware {
            default_params,
            write_params,
            encode_with,
            step_with,
            hash: manifest.hash,
            _lib: lib,
        };
        if fw.default_params() != manifest.runtime_defaults {
            return Err(bad(
                "the C's default parameters differ from the manifest's: export them again together"
                    .into(),
            ));
        }
        Ok(fw)
    }

    /// The hash of the policy this firmware carries.
    pub fn hash(&self) -> u32 {
        self.hash
    }

    /// `<prefix>_default_params`.
    pub fn default_params(&self) -> Vec<f32> {
        let mut p = vec![0.0f32; RUNTIME_LEN];
        // SAFETY: `p` holds the block's `RUNTIME_LEN` values.
        unsafe { (self.default_params)(p.as_mut_ptr()) };
        p
    }

    /// `<prefix>_write_params`: whether the firmware took the values.
    pub fn write_params(
        &self,
        params: &mut [f32],
        offset: u16,
        count: u8,
        values: &[f32; 5],
    ) -> bool {
        if params.len() != RUNTIME_LEN || count > 5 {
            return false;
        }
        // SAFETY: `params` is a whole block; the C reads at most `count` <= 5 of `values`.
        unsafe { (self.write_params)(params.as_mut_ptr(), offset, count, values.as_ptr()) == 1 }
    }

    /// `<prefix>_encode_with`: the 17 observations the policy sees for raw readings and the wheel
    /// speeds last chosen.
    pub fn encode(&self, params: &[f32], raw: &RawReadings, last: (f32, f32)) -> [f32; 17] {
        let mut obs = [0.0f32; 17];
        if params.len() == RUNTIME_LEN {
            let (colour, ir_on, ir_off) = raw.ptrs();
            // SAFETY: sizes as the header declares them; `obs` holds the 17 outputs.
            unsafe {
                (self.encode_with)(
                    params.as_ptr(),
                    colour,
                    ir_on,
                    ir_off,
                    last.0,
                    last.1,
                    obs.as_mut_ptr(),
                )
            };
        }
        obs
    }

    /// `<prefix>_step_with`: the wheel speeds (m/s) the policy chooses from raw readings, `last` the
    /// speeds it chose before.
    pub fn step(&self, params: &[f32], raw: &RawReadings, last: (f32, f32)) -> (f32, f32) {
        if params.len() != RUNTIME_LEN {
            return (0.0, 0.0);
        }
        let (mut left, mut right) = last;
        let (colour, ir_on, ir_off) = raw.ptrs();
        // SAFETY: sizes as the header declares them: 59 params, 12 colour counts, 3 + 3 bumper counts.
        unsafe {
            (self.step_with)(
                params.as_ptr(),
                colour,
                ir_on,
                ir_off,
                &mut left,
                &mut right,
            )
        };
        (left, right)
    }
}

/// A robot's raw readings as its firmware takes them: the colour counts (in the telemetry's order)
/// and the IR bumpers' counts with the emitters on and off.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RawReadings {
    pub colour: [[u16; 3]; 4],
    pub ir_on: [u16; 3],
    pub ir_off: [u16; 3],
}

impl RawReadings {
    /// The arrays as the C takes them: 12 colour counts, 3 and 3 bumper counts.
    fn ptrs(&self) -> (*const u16, *const u16, *const u16) {
        (
            self.colour.as_flattened().as_ptr(),
            self.ir_on.as_ptr(),
            self.ir_off.as_ptr(),
        )
    }
}

/// A fresh file name for one build (several twins may build at once).
fn scratch_path(hash: u32) -> PathBuf {
    use std::sync::atomic::{AtomicU64, Ordering};
    static BUILDS: AtomicU64 = AtomicU64::new(0);
    let k = BUILDS.fetch_add(1, Ordering::Relaxed);
    std::env::temp_dir().join(format!(
        "colcos-onboard-{}-{k}-{hash:08x}.so",
        std::process::id()
    ))
}
